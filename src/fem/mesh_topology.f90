!> One body's mesh from what a mesh file holds (physical groups, entities, nodes, cells,
!! lines and points, in file order; module gmsh_msh reads them): the cells of the body's
!! physical surface, its cells counter-clockwise (degenerate cells and non-convex
!! quadrangles refused), and its groups. Its nodes and cells are checked in the file's
!! order (the body's nodes by increasing tag), then numbered for locality
!! (number_for_locality; mesh%file_node and mesh%file_cell keep the file's order).
!! A group keeps the line elements of its physical curve that are boundary edges of the body
!! (edges of exactly one body cell), oriented as that cell traverses them; the nodes of its
!! lines inside the body (edges of two body cells) are kept as single nodes. A physical point
!! is a group of single nodes: those of its points that are nodes of the body. A point's
!! node in no cell of the file (a free geometry point) is the body's node at the same place,
!! within 1e-9 times the body's size, if it has one.
module mesh_topology
  use kinds, only: wp, i8
  use config, only: ELEM_Q1, ELEM_P1, ELEM_MIXED, shape_vertices
  use errors, only: error_t, ERR_INPUT, ERR_MEMORY
  use strings, only: i2s, sci, text_buffer_t
  use int_hash, only: int_hash_t, hash_init, hash_slot, HASH_EMPTY
  use sorting, only: merge_sort_by_keys
  use mesh, only: mesh_t, cell_group_t
  implicit none (type, external)
  private

  public :: body_from_file, body_group, add_physical, index_entities, entity_index, index_groups
  ! for the volume meshes of module volume_topology
  public :: group_members, entity_cells, cell_regions, point_groups, number_for_locality, &
            check_one_piece, sort_by_tag, body_file_nodes

  real(wp), parameter :: AREA_TOL = 1.0e-12_wp       ! degenerate: |area| < AREA_TOL * (longest edge)^2
  ! the largest coordinate whose cell areas and squared edges stay finite (8 x^2 <= huge)
  real(wp), parameter :: COORD_MAX = 0.25_wp*sqrt(huge(1.0_wp))

  !> A text of its own length (an array of names).
  type, public :: name_t
    character(len=:), allocatable :: s
  end type name_t

  !> A point, curve or surface entity (in a 3D run also a volume) and its physical tags.
  type, public :: entity_t
    integer :: dim = 0, tag = 0
    integer, allocatable :: phys(:)
  end type entity_t

  !> What a mesh file holds, before a body is chosen. Nodes, cells, lines and points are
  !! numbered in file order; elements refer to nodes by that number, to entities by their
  !! index in `ent` (0: the file has no entity for them).
  type, public :: file_mesh_t
    integer :: nphys = 0                       !< physical groups (named or not)
    integer, allocatable :: phys_dim(:), phys_tag(:)  !< dimension 0..3 and tag of each
    type(name_t), allocatable :: phys_name(:)
    type(int_hash_t) :: phys_hash              !< the groups' keys (group_key)
    integer, allocatable :: phys_of_slot(:)    !< (0:phys_hash%mask) the group in each slot
    integer :: nent = 0                        !< point, curve and surface entities (3D: and volumes)
    type(entity_t), allocatable :: ent(:)
    type(int_hash_t) :: ent_hash               !< the entities' keys (group_key), by index_entities
    integer, allocatable :: ent_of_slot(:)     !< (0:ent_hash%mask) the entity in each slot
    integer :: nnode = 0                       !< nodes
    integer, allocatable :: node_tag(:)
    real(wp), allocatable :: node_xy(:, :)     !< (2, nnode); 3D: (3, nnode)
    integer :: ncell = 0                       !< triangles and quadrangles (3D: tetrahedra and hexahedra)
    integer, allocatable :: cell_tag(:), cell_entity(:)
    !> (4, ncell) nodes; a triangle's 4th is 0 (3D: (8, ncell), a tetrahedron's 5th to 8th are 0)
    integer, allocatable :: cell_node(:, :)
    integer :: nface = 0                       !< 3D: triangles and quadrangles (the faces of surfaces)
    integer, allocatable :: face_tag(:), face_entity(:)
    integer, allocatable :: face_node(:, :)    !< (4, nface) nodes; a triangle's 4th is 0
    integer :: nline = 0                       !< 2-node lines
    integer, allocatable :: line_tag(:), line_entity(:), line_node(:, :)
    integer :: npoint = 0                      !< point elements
    integer, allocatable :: point_entity(:), point_node(:)
    !> by index_groups, once for all the bodies of the file (absent: each body finds what
    !! it needs in the whole file): the points of each physical group (group_members), the
    !! lines starting at each node (node k's: node_lines(node_line_first(k):
    !! node_line_first(k + 1) - 1))
    integer, allocatable :: point_first(:), point_members(:), node_line_first(:), node_lines(:)
    !> the cells of each entity, in file order: those of entity e are
    !! ent_cells(ent_cell_first(e):ent_cell_first(e + 1) - 1), e = 0..nent (by index_groups)
    integer, allocatable :: ent_cell_first(:), ent_cells(:)
  end type file_mesh_t

contains

  !> The hash key of a physical group or entity (dim, tag), dim 0..3: non-negative.
  pure integer(i8) function group_key(dim, tag)
    integer, intent(in) :: dim, tag
    group_key = int(dim, i8)*2_i8**32 + (int(tag, i8) + 2_i8**31)
  end function group_key

  !> Add a physical group (dim, tag), dim 0..3, named `name` unless it is there already
  !! (looked up through a hash table, so many groups cost linear time). err (ERR_MEMORY):
  !! out of memory.
  subroutine add_physical(file_mesh, dim, tag, name, err)
    type(file_mesh_t), intent(inout) :: file_mesh
    integer, intent(in) :: dim, tag
    character(len=*), intent(in) :: name
    type(error_t), intent(out) :: err     !< ERR_MEMORY: no room for the groups
    integer, allocatable :: idim(:), itag(:)
    type(name_t), allocatable :: nm(:)
    integer :: k, slot, st
    integer(i8) :: key
    st = 0
    if (.not. allocated(file_mesh%phys_dim)) &
      allocate (file_mesh%phys_dim(8), file_mesh%phys_tag(8), file_mesh%phys_name(8), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for the physical groups')
      return
    end if
    if (2_i8*(file_mesh%nphys + 1) > file_mesh%phys_hash%mask + 1) then   ! keep the table at most half full
      call hash_init(file_mesh%phys_hash, 2*(file_mesh%nphys + 1), err)
      if (.not. err%failed()) then
        if (allocated(file_mesh%phys_of_slot)) deallocate (file_mesh%phys_of_slot)
        allocate (file_mesh%phys_of_slot(0:file_mesh%phys_hash%mask), stat=st)
      end if
      if (err%failed() .or. st /= 0) then
        call err%set(ERR_MEMORY, 'not enough memory for the physical groups')
        return
      end if
      do k = 1, file_mesh%nphys
        key = group_key(file_mesh%phys_dim(k), file_mesh%phys_tag(k))
        slot = hash_slot(file_mesh%phys_hash, key)
        file_mesh%phys_hash%key(slot) = key
        file_mesh%phys_of_slot(slot) = k
      end do
    end if
    key = group_key(dim, tag)
    slot = hash_slot(file_mesh%phys_hash, key)
    if (file_mesh%phys_hash%key(slot) == key) return
    if (file_mesh%nphys == size(file_mesh%phys_dim)) then
      allocate (idim(2*file_mesh%nphys), itag(2*file_mesh%nphys), nm(2*file_mesh%nphys), stat=st)
      if (st /= 0) then
        call err%set(ERR_MEMORY, 'not enough memory for the physical groups')
        return
      end if
      idim(1:file_mesh%nphys) = file_mesh%phys_dim
      itag(1:file_mesh%nphys) = file_mesh%phys_tag
      do k = 1, file_mesh%nphys
        call move_alloc(file_mesh%phys_name(k)%s, nm(k)%s)
      end do
      call move_alloc(idim, file_mesh%phys_dim)
      call move_alloc(itag, file_mesh%phys_tag)
      call move_alloc(nm, file_mesh%phys_name)
    end if
    file_mesh%nphys = file_mesh%nphys + 1
    file_mesh%phys_dim(file_mesh%nphys) = dim
    file_mesh%phys_tag(file_mesh%nphys) = tag
    file_mesh%phys_name(file_mesh%nphys)%s = name
    file_mesh%phys_hash%key(slot) = key
    file_mesh%phys_of_slot(slot) = file_mesh%nphys
  end subroutine add_physical

  !> Hash the entities (dim 0..2; 3D: 0..3) for entity_index; of two with the same dimension and tag
  !! the first is found. err (ERR_MEMORY): out of memory.
  subroutine index_entities(file_mesh, err)
    type(file_mesh_t), intent(inout) :: file_mesh
    type(error_t), intent(out) :: err     !< ERR_MEMORY: no room for the index
    integer :: k, slot, st
    integer(i8) :: key
    st = 0
    call hash_init(file_mesh%ent_hash, file_mesh%nent, err)
    if (.not. err%failed()) allocate (file_mesh%ent_of_slot(0:file_mesh%ent_hash%mask), stat=st)
    if (err%failed() .or. st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for the entities')
      return
    end if
    do k = 1, file_mesh%nent
      key = group_key(file_mesh%ent(k)%dim, file_mesh%ent(k)%tag)
      slot = hash_slot(file_mesh%ent_hash, key)
      if (file_mesh%ent_hash%key(slot) == key) cycle
      file_mesh%ent_hash%key(slot) = key
      file_mesh%ent_of_slot(slot) = k
    end do
  end subroutine index_entities

  !> The index in file_mesh%ent of entity (dim, tag), 0 if it has none (or dim is not 0..3;
  !! a 2D run keeps no volume).
  integer function entity_index(file_mesh, dim, tag) result(k)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: dim, tag
    integer :: slot
    integer(i8) :: key
    k = 0
    if (.not. allocated(file_mesh%ent_of_slot) .or. dim < 0 .or. dim > 3) return
    key = group_key(dim, tag)
    slot = hash_slot(file_mesh%ent_hash, key)
    if (file_mesh%ent_hash%key(slot) == key) k = file_mesh%ent_of_slot(slot)
  end function entity_index

  !> The members of every physical group of points (file_mesh%point_first, ...), the lines
  !! starting at each node and the cells of every entity (counting sorts, in file order),
  !! once for all the bodies of the file. Out of memory: left absent.
  subroutine index_groups(file_mesh)
    type(file_mesh_t), intent(inout) :: file_mesh
    type(error_t) :: err
    call bucket_items(file_mesh%cell_entity(1:file_mesh%ncell), 0, file_mesh%nent, file_mesh%ent_cell_first, &
                      file_mesh%ent_cells, err)
    if (err%failed()) then
      if (allocated(file_mesh%ent_cell_first)) deallocate (file_mesh%ent_cell_first)
      if (allocated(file_mesh%ent_cells)) deallocate (file_mesh%ent_cells)
    end if
    call group_members(file_mesh, 0, file_mesh%point_entity(1:file_mesh%npoint), &
                       file_mesh%point_first, file_mesh%point_members, err)
    if (err%failed()) then
      if (allocated(file_mesh%point_first)) deallocate (file_mesh%point_first)
      if (allocated(file_mesh%point_members)) deallocate (file_mesh%point_members)
    end if
    call bucket_items(file_mesh%line_node(1, 1:file_mesh%nline), 1, file_mesh%nnode, file_mesh%node_line_first, &
                      file_mesh%node_lines, err)
    if (err%failed()) then
      if (allocated(file_mesh%node_line_first)) deallocate (file_mesh%node_line_first)
      if (allocated(file_mesh%node_lines)) deallocate (file_mesh%node_lines)
    end if
  end subroutine index_groups

  !> Items 1..size(key) bucketed by their key in [lo, hi] (a counting sort, items in
  !! increasing order within a bucket): bucket k holds members(first(k):first(k+1)-1).
  !! err (ERR_MEMORY): out of memory.
  subroutine bucket_items(key, lo, hi, first, members, err)
    integer, intent(in) :: key(:), lo, hi
    integer, allocatable, intent(out) :: first(:), members(:)
    type(error_t), intent(out) :: err
    integer, allocatable :: fill(:)
    integer :: i, k, st
    allocate (first(lo:hi + 1), members(size(key)), fill(lo:hi), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to bucket '//i2s(size(key))//' items')
      return
    end if
    fill = 0
    do i = 1, size(key)
      fill(key(i)) = fill(key(i)) + 1
    end do
    first(lo) = 1
    do k = lo, hi
      first(k + 1) = first(k) + fill(k)
    end do
    fill = 0
    do i = 1, size(key)
      k = key(i)
      members(first(k) + fill(k)) = i
      fill(k) = fill(k) + 1
    end do
  end subroutine bucket_items

  !> The physical group of dimension `dim` (2: a surface, 3: a volume) that is the body:
  !! the one named `region`, or with region = '' the file's only one (0 when the file has
  !! none: every cell of that dimension is the body). err (ERR_INPUT, a phrase about the file)
  !! when no group has that name (`hint` appended) or region = '' and there are several.
  subroutine body_group(file_mesh, region, dim, hint, group, err)
    type(file_mesh_t), intent(in) :: file_mesh   !< the file's physical groups
    character(len=*), intent(in) :: region       !< the body's group name, or ''
    integer, intent(in) :: dim                   !< 2 or 3
    character(len=*), intent(in) :: hint         !< appended to a 'has no physical ...' message
    integer, intent(out) :: group                !< its index in file_mesh%phys_*, 0: none
    type(error_t), intent(out) :: err
    integer :: k, n
    character(len=:), allocatable :: noun, names
    type(text_buffer_t) :: list
    noun = trim(merge('surface', 'volume ', dim == 2))
    n = 0
    group = 0
    do k = 1, file_mesh%nphys
      if (file_mesh%phys_dim(k) /= dim) cycle
      n = n + 1
      if (len(region) > 0) then
        if (file_mesh%phys_name(k)%s == region) group = k
      end if
    end do
    if ((len(region) > 0 .and. group == 0) .or. (len(region) == 0 .and. n > 1)) then
      n = 0                    ! their names, for the message
      do k = 1, file_mesh%nphys
        if (file_mesh%phys_dim(k) /= dim) cycle
        n = n + 1
        call list%add(merge(', ', '  ', n > 1)//"'"//file_mesh%phys_name(k)%s//"'")
      end do
      call list%get(names)
      names = trim(adjustl(names))
    end if
    if (len(region) > 0 .and. group == 0) then
      if (n == 0) then
        call err%set(ERR_INPUT, "has no physical "//noun//" '"//region//"' (it has no physical "//noun//"s)"//hint)
      else
        call err%set(ERR_INPUT, "has no physical "//noun//" '"//region//"' (its physical "//noun//"s: "//names//')'// &
                     hint)
      end if
      return
    end if
    if (len(region) == 0 .and. n > 1) then
      call err%set(ERR_INPUT, 'holds '//i2s(n)//' physical '//noun//'s ('//names//'); name the body''s one as its region')
      return
    end if
    if (len(region) == 0 .and. n == 1) then
      do k = 1, file_mesh%nphys
        if (file_mesh%phys_dim(k) == dim) group = k
      end do
    end if
  end subroutine body_group

  !> One body from what a mesh file holds: choose the body's cells (those of the physical
  !! surface `region`), number its nodes by tag, orient and check its cells, find its
  !! groups, then number its nodes and cells for locality (number_for_locality). On failure err holds ERR_INPUT (bad input) or ERR_MEMORY and a phrase about the file
  !! (its subject the file: 'has no physical surface ...').
  subroutine body_from_file(file_mesh, region, path, mesh, err)
    type(file_mesh_t), intent(in), target :: file_mesh  !< the file's groups, entities, nodes, elements
    character(len=*), intent(in) :: region              !< physical surface name of the body, or ''
    character(len=*), intent(in) :: path                !< the file, kept as mesh%source
    type(mesh_t), intent(inout) :: mesh                 !< the body's mesh
    type(error_t), intent(out) :: err                   !< the failure, if any
    integer :: surface, k, c, ncell, nquad
    logical, allocatable :: in_entity(:)
    integer, allocatable :: file_cell(:), body_node(:), order(:)

    ! the physical surface of the body
    call body_group(file_mesh, region, 2, '', surface, err)
    if (err%failed()) return

    ! its cells: those of the surface entities in the group (every one without a group)
    allocate (in_entity(0:file_mesh%nent))
    in_entity = surface == 0
    do k = 1, file_mesh%nent
      if (surface > 0) in_entity(k) = file_mesh%ent(k)%dim == 2 .and. &
                                      any(file_mesh%ent(k)%phys == file_mesh%phys_tag(surface))
    end do
    file_cell = entity_cells(file_mesh, in_entity)
    ncell = size(file_cell)
    if (ncell == 0) then
      if (surface > 0) then
        if (file_mesh%nent == 0) then
          call err%set(ERR_INPUT, "names physical surface '"//file_mesh%phys_name(surface)%s// &
                       "' but has no $Entities section, which ties elements to physical groups")
        else
          call err%set(ERR_INPUT, "physical surface '"//file_mesh%phys_name(surface)%s// &
                       "' has no triangles or quadrangles")
        end if
      else
        call err%set(ERR_INPUT, 'has no triangles or quadrangles')
      end if
      return
    end if

    ! its nodes, in increasing tag order
    call body_file_nodes(file_mesh, file_cell, 4, body_node, order, err)
    if (err%failed()) return
    mesh%nnode = size(order)
    allocate (mesh%xy(2, mesh%nnode), mesh%node_tag(mesh%nnode))
    do k = 1, mesh%nnode
      body_node(order(k)) = k
      mesh%xy(:, k) = file_mesh%node_xy(:, order(k))
      mesh%node_tag(k) = file_mesh%node_tag(order(k))
    end do
    do k = 1, mesh%nnode
      if (maxval(abs(mesh%xy(:, k))) > COORD_MAX) then
        call err%set(ERR_INPUT, 'node '//i2s(mesh%node_tag(k))//' has a coordinate of magnitude '// &
                     sci(maxval(abs(mesh%xy(:, k))))//': beyond '//sci(COORD_MAX)// &
                     ' the cells'' areas overflow double precision; scale the mesh')
        return
      end if
    end do

    ! its cells
    nquad = count(file_mesh%cell_node(4, file_cell) > 0)
    mesh%ncell = ncell
    mesh%nvert = merge(4, 3, nquad > 0)
    if (nquad == ncell) then
      mesh%element = ELEM_Q1
    else if (nquad == 0) then
      mesh%element = ELEM_P1
    else
      mesh%element = ELEM_MIXED
    end if
    allocate (mesh%cells(mesh%nvert, ncell), mesh%cell_type(ncell), mesh%cell_tag(ncell))
    mesh%cells = 0
    do k = 1, ncell
      c = file_cell(k)
      mesh%cell_tag(k) = file_mesh%cell_tag(c)
      if (file_mesh%cell_node(4, c) > 0) then
        mesh%cell_type(k) = ELEM_Q1
        mesh%cells(1:4, k) = body_node(file_mesh%cell_node(1:4, c))
      else
        mesh%cell_type(k) = ELEM_P1
        mesh%cells(1:3, k) = body_node(file_mesh%cell_node(1:3, c))
      end if
      call orient_cell(mesh, k, err)
      if (err%failed()) return
    end do
    call check_duplicate_cells(mesh, err)
    if (err%failed()) return
    call check_overlapping_cells(mesh, err)
    if (err%failed()) return
    call check_one_piece(mesh, err)
    if (err%failed()) return

    mesh%structured = .false.
    mesh%source = path
    mesh%nx = 0
    mesh%ny = 0
    mesh%x0 = minval(mesh%xy(1, :))
    mesh%y0 = minval(mesh%xy(2, :))
    mesh%width = maxval(mesh%xy(1, :)) - mesh%x0
    mesh%height = maxval(mesh%xy(2, :)) - mesh%y0

    call cell_regions(file_mesh, 2, surface, file_cell, mesh)
    call boundary_groups(file_mesh, body_node, order, mesh, err)
    if (.not. err%failed()) call point_groups(file_mesh, body_node, mesh, err)
    if (.not. err%failed()) call number_for_locality(mesh, err)
  end subroutine body_from_file

  !> The body's regions: each physical surface (dim = 2; a volume mesh's: physical volume,
  !! dim = 3) of the file other than the body's own (`surface`) that holds cells of the body,
  !! with those cells (in file order, as numbered before number_for_locality).
  subroutine cell_regions(file_mesh, dim, surface, file_cell, mesh)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: dim               ! the cells' dimension: 2, or 3
    integer, intent(in) :: surface           ! the body's physical surface (volume), 0: none
    integer, intent(in) :: file_cell(:)      ! the body's cells in the file
    type(mesh_t), intent(inout) :: mesh
    integer :: k, c, e, n
    integer, allocatable :: cells(:)
    type(cell_group_t), allocatable :: tmp(:)
    mesh%nregion = 0
    allocate (mesh%region(0), cells(size(file_cell)))
    do k = 1, file_mesh%nphys
      if (file_mesh%phys_dim(k) /= dim .or. k == surface) cycle
      n = 0
      do c = 1, size(file_cell)
        e = file_mesh%cell_entity(file_cell(c))
        if (e == 0) cycle
        if (any(file_mesh%ent(e)%phys == file_mesh%phys_tag(k))) then
          n = n + 1
          cells(n) = c
        end if
      end do
      if (n == 0) cycle
      allocate (tmp(mesh%nregion + 1))
      tmp(1:mesh%nregion) = mesh%region
      tmp(mesh%nregion + 1)%name = file_mesh%phys_name(k)%s
      tmp(mesh%nregion + 1)%cell = cells(1:n)
      call move_alloc(tmp, mesh%region)
      mesh%nregion = mesh%nregion + 1
    end do
  end subroutine cell_regions

  !> The file's cells of the entities with in_entity(e) (e = 0..nent), in file order:
  !! from the cells of each entity (file_mesh%ent_cells) when those of several entities
  !! do not interleave, else by one pass over the file's cells.
  function entity_cells(file_mesh, in_entity) result(cells)
    type(file_mesh_t), intent(in) :: file_mesh
    logical, intent(in) :: in_entity(0:)
    integer, allocatable :: cells(:)
    integer :: e, n, lo, hi
    if (allocated(file_mesh%ent_cell_first)) then
      n = 0
      do e = 0, file_mesh%nent
        if (in_entity(e)) n = n + file_mesh%ent_cell_first(e + 1) - file_mesh%ent_cell_first(e)
      end do
      allocate (cells(n))
      n = 0
      do e = 0, file_mesh%nent
        if (.not. in_entity(e)) cycle
        lo = file_mesh%ent_cell_first(e)
        hi = file_mesh%ent_cell_first(e + 1) - 1
        cells(n + 1:n + hi - lo + 1) = file_mesh%ent_cells(lo:hi)
        n = n + hi - lo + 1
      end do
      if (n < 2) return
      if (all(cells(2:n) > cells(1:n - 1))) return
    end if
    cells = pack([(e, e=1, file_mesh%ncell)], in_entity(file_mesh%cell_entity(1:file_mesh%ncell)))
  end function entity_cells

  !> Renumber the body's nodes along a Morton (Z-order) curve of their coordinates, and
  !! its cells by their smallest node in that numbering: the nodes of a neighbourhood get
  !! nearby numbers, so the stiffness columns of a cell lie close together and the element
  !! loop walks the matrix in order. The file's order is kept in file_node and file_cell
  !! (the order of the output); groups follow the new numbers. err: ERR_MEMORY. In space
  !! (mesh%xy of 3 rows) the key interleaves 10 bits of each of x, y, z.
  subroutine number_for_locality(mesh, err)
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(inout) :: err
    integer, parameter :: BITS = 15                     ! per coordinate of the Morton key (morton's)
    integer, parameter :: BITS3 = 10                    ! per coordinate in space (morton3's)
    integer, allocatable :: key(:), order(:), new_node(:), first(:), new_cell(:)
    real(wp) :: lo(size(mesh%xy, 1)), scale(size(mesh%xy, 1))
    integer :: k, c, g, q(size(mesh%xy, 1)), st, i

    allocate (key(mesh%nnode), new_node(mesh%nnode), first(mesh%nnode + 1), new_cell(mesh%ncell), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to renumber '//i2s(mesh%nnode)//' nodes')
      return
    end if
    lo = minval(mesh%xy, dim=2)
    if (size(mesh%xy, 1) == 2) then
      scale = real(2**BITS - 1, wp)/max(maxval(mesh%xy, dim=2) - lo, tiny(1.0_wp))
      do k = 1, mesh%nnode
        q = min(max(int((mesh%xy(:, k) - lo)*scale), 0), 2**BITS - 1)
        key(k) = morton(q(1), q(2))
      end do
      call radix_order(key, 2*BITS, order)
    else
      scale = real(2**BITS3 - 1, wp)/max(maxval(mesh%xy, dim=2) - lo, tiny(1.0_wp))
      do k = 1, mesh%nnode
        q = min(max(int((mesh%xy(:, k) - lo)*scale), 0), 2**BITS3 - 1)
        key(k) = morton3(q(1), q(2), q(3))
      end do
      call radix_order(key, 3*BITS3, order)
    end if
    new_node(order) = [(k, k=1, mesh%nnode)]
    call move_alloc(order, mesh%file_node)
    mesh%xy = mesh%xy(:, mesh%file_node)
    mesh%node_tag = mesh%node_tag(mesh%file_node)
    do c = 1, mesh%ncell
      do k = 1, mesh%nvert
        if (mesh%cells(k, c) > 0) mesh%cells(k, c) = new_node(mesh%cells(k, c))
      end do
    end do
    do g = 1, mesh%ngroup
      do k = 1, mesh%group(g)%nedge
        do i = 1, size(mesh%group(g)%edge, 1)      ! a triangle among quadrangles: a 0 in row 4
          if (mesh%group(g)%edge(i, k) > 0) mesh%group(g)%edge(i, k) = new_node(mesh%group(g)%edge(i, k))
        end do
      end do
      if (allocated(mesh%group(g)%node)) mesh%group(g)%node = new_node(mesh%group(g)%node)
    end do

    ! cells by their smallest node (a stable counting sort)
    first = 0
    do c = 1, mesh%ncell
      k = minval(mesh%cells(:, c), mask=mesh%cells(:, c) > 0)
      first(k + 1) = first(k + 1) + 1
    end do
    first(1) = 1
    do k = 1, mesh%nnode
      first(k + 1) = first(k + 1) + first(k)
    end do
    do c = 1, mesh%ncell
      k = minval(mesh%cells(:, c), mask=mesh%cells(:, c) > 0)
      new_cell(c) = first(k)
      first(k) = first(k) + 1
    end do
    allocate (mesh%file_cell(mesh%ncell))
    mesh%file_cell(new_cell) = [(c, c=1, mesh%ncell)]
    mesh%cells = mesh%cells(:, mesh%file_cell)
    mesh%cell_type = mesh%cell_type(mesh%file_cell)
    mesh%cell_tag = mesh%cell_tag(mesh%file_cell)
    do g = 1, mesh%ngroup
      if (allocated(mesh%group(g)%cell)) mesh%group(g)%cell = new_cell(mesh%group(g)%cell)
    end do
    do g = 1, mesh%nregion
      mesh%region(g)%cell = new_cell(mesh%region(g)%cell)
    end do
  end subroutine number_for_locality

  !> The Morton key of (i, j), each 0 <= i, j < 2**15: their bits interleaved, i's in the
  !! even places.
  pure integer function morton(i, j) result(key)
    integer, intent(in) :: i, j
    key = ior(spread_bits(i), ishft(spread_bits(j), 1))
  end function morton

  !> The Morton key of (i, j, k), each 0 <= i, j, k < 2**10: their bits interleaved, i's in
  !! the places 0, 3, 6, ..., j's in 1, 4, ..., k's in 2, 5, ... (30 bits).
  pure integer function morton3(i, j, k) result(key)
    integer, intent(in) :: i, j, k
    key = ior(ior(spread_bits3(i), ishft(spread_bits3(j), 1)), ishft(spread_bits3(k), 2))
  end function morton3

  !> The 10 low bits of x moved to every third place (bit b to bit 3 b), by halving shifts.
  pure integer function spread_bits3(x) result(y)
    integer, intent(in) :: x
    y = iand(x, int(z'3FF'))
    y = iand(ior(y, ishft(y, 16)), int(z'030000FF'))
    y = iand(ior(y, ishft(y, 8)), int(z'0300F00F'))
    y = iand(ior(y, ishft(y, 4)), int(z'030C30C3'))
    y = iand(ior(y, ishft(y, 2)), int(z'09249249'))
  end function spread_bits3

  !> The 15 low bits of x moved to the even places (bit b to bit 2 b), by halving shifts.
  pure integer function spread_bits(x) result(y)
    integer, intent(in) :: x
    y = iand(x, int(z'7FFF'))
    y = iand(ior(y, ishft(y, 8)), int(z'00FF00FF'))
    y = iand(ior(y, ishft(y, 4)), int(z'0F0F0F0F'))
    y = iand(ior(y, ishft(y, 2)), int(z'33333333'))
    y = iand(ior(y, ishft(y, 1)), int(z'55555555'))
  end function spread_bits

  !> The indices 1..size(key) by increasing key (keys of `nbits` bits, non-negative):
  !! a stable least-significant-digit radix sort, two digits; fewer keys than an eighth of
  !! a digit's range (a small body, whose counts would cost more than the keys) by a
  !! stable merge sort, the same order.
  subroutine radix_order(key, nbits, order)
    integer, intent(in) :: key(:)
    integer, intent(in) :: nbits
    integer, allocatable, intent(out) :: order(:)
    integer, allocatable :: count(:), tmp(:)
    integer :: n, i, d, shift, width, digit
    n = size(key)
    width = (nbits + 1)/2
    if (n < 2**width/8) then
      order = [(i, i=1, n)]
      call merge_sort_by_keys(order, reshape(key, [1, n]))
      return
    end if
    allocate (order(n), tmp(n), count(0:2**width))
    order = [(i, i=1, n)]
    do d = 0, 1
      shift = d*width
      count = 0
      do i = 1, n
        digit = ibits(key(i), shift, width)
        count(digit + 1) = count(digit + 1) + 1
      end do
      do i = 1, 2**width
        count(i) = count(i) + count(i - 1)
      end do
      do i = 1, n
        digit = ibits(key(order(i)), shift, width)
        count(digit) = count(digit) + 1
        tmp(count(digit)) = order(i)
      end do
      order = tmp
    end do
  end subroutine radix_order

  !> Put cell k counter-clockwise; refuse it if degenerate or (a quadrangle) not convex.
  subroutine orient_cell(mesh, k, err)
    type(mesh_t), intent(inout) :: mesh
    integer, intent(in) :: k
    type(error_t), intent(inout) :: err
    real(wp) :: p(2, 4), area2, h2, turn
    integer :: nv, i, i1, i2
    character(len=*), parameter :: what(2) = ['quadrangle', 'triangle  ']

    nv = merge(4, 3, mesh%cell_type(k) == ELEM_Q1)
    do i = 1, nv
      p(:, i) = mesh%xy(:, mesh%cells(i, k))
    end do
    area2 = 0.0_wp
    h2 = 0.0_wp
    do i = 1, nv
      i1 = modulo(i, nv) + 1
      area2 = area2 + p(1, i)*p(2, i1) - p(1, i1)*p(2, i)
      h2 = max(h2, sum((p(:, i1) - p(:, i))**2))
    end do
    if (.not. abs(area2) > 2.0_wp*AREA_TOL*h2) then
      call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' (a '//trim(what(mesh%cell_type(k)))// &
                ') is degenerate: its area is zero or nearly so')
      return
    end if
    if (area2 < 0.0_wp) then      ! clockwise: reverse, keeping the first vertex
      mesh%cells(2:nv, k) = mesh%cells(nv:2:-1, k)
      p(:, 2:nv) = p(:, nv:2:-1)
    end if
    if (nv == 4) then
      do i = 1, 4
        i1 = modulo(i, 4) + 1
        i2 = modulo(i + 1, 4) + 1
        turn = (p(1, i1) - p(1, i))*(p(2, i2) - p(2, i1)) - (p(2, i1) - p(2, i))*(p(1, i2) - p(1, i1))
        if (.not. turn > AREA_TOL*h2) then
          call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' is not a convex quadrangle '// &
                    '(inverted, self-crossing or with a re-entrant or straight corner at node '// &
                    i2s(mesh%node_tag(mesh%cells(i1, k)))//')')
          return
        end if
      end do
    end if
  end subroutine orient_cell

  !> One edge group per physical curve: its lines that are boundary edges of the body, and
  !! the nodes of its lines inside the body as single nodes (a curve inside the body gives
  !! a group of nodes only). A line whose two nodes are in the body but are not an edge of
  !! any of its cells (a corrupted node number) is bad input: its condition would be lost. The lines' edges are hashed (a small table), then every cell
  !! edge between two nodes of lines is looked up in it: a line edge met in exactly one cell
  !! is a boundary edge, oriented as that cell has it; one met in two is inside the body.
  subroutine boundary_groups(file_mesh, body_node, file_node, mesh, err)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    integer, intent(in) :: file_node(:)   ! body node -> file node index
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(inout) :: err
    type(int_hash_t) :: edge_hash
    integer, allocatable :: line_slot(:), edge_count(:), edge_cell(:), edge_local(:), edges(:, :), cells(:), inner(:)
    integer, allocatable :: seen_group(:), seen_line(:), first(:), members(:), cand(:), perm(:)
    logical, allocatable :: marked(:), on_line(:)
    integer :: c, i, nv, a, b, slot, st, phys, line, nedge, ngroup, ninner, m, j, ncand, k
    integer(i8) :: key, key_base
    type(text_buffer_t) :: names
    type(error_t) :: mem

    ! the candidate lines, in file order: those starting at a node of the body when it is a
    ! small part of the file (node_lines), else all
    if (allocated(file_mesh%node_line_first) .and. 8*int(mesh%nnode, i8) < file_mesh%nnode) then
      ncand = 0
      do k = 1, mesh%nnode
        ncand = ncand + file_mesh%node_line_first(file_node(k) + 1) - file_mesh%node_line_first(file_node(k))
      end do
      allocate (cand(ncand))
      ncand = 0
      do k = 1, mesh%nnode
        do j = file_mesh%node_line_first(file_node(k)), file_mesh%node_line_first(file_node(k) + 1) - 1
          ncand = ncand + 1
          cand(ncand) = file_mesh%node_lines(j)
        end do
      end do
      perm = [(j, j=1, ncand)]
      call merge_sort_by_keys(perm, reshape(cand, [1, ncand]))
      cand = cand(perm)
    else
      ncand = file_mesh%nline
      cand = [(j, j=1, ncand)]
    end if

    ! the body's line edges, keyed by their two nodes (line_slot = -1: not a body edge)
    st = 0
    call hash_init(edge_hash, ncand, mem)
    if (.not. mem%failed()) allocate (line_slot(ncand), edge_count(0:edge_hash%mask), edge_cell(0:edge_hash%mask), &
                                      edge_local(0:edge_hash%mask), edges(2, ncand), cells(ncand), &
                                      inner(2*ncand), marked(mesh%nnode), on_line(mesh%nnode), &
                                      seen_group(0:edge_hash%mask), &
                                      seen_line(0:edge_hash%mask), stat=st)
    if (st == 0 .and. .not. mem%failed()) call group_members(file_mesh, 1, file_mesh%line_entity(cand), first, members, mem)
    if (st /= 0 .or. mem%failed()) then
      call err%set(ERR_MEMORY, 'not enough memory for the boundary edges')
      return
    end if
    line_slot = -1
    edge_count = 0
    seen_group = 0
    marked = .false.
    on_line = .false.
    key_base = mesh%nnode + 1
    do j = 1, ncand
      line = cand(j)
      if (file_mesh%line_entity(line) == 0) cycle
      a = body_node(file_mesh%line_node(1, line))
      b = body_node(file_mesh%line_node(2, line))
      if (a == 0 .or. b == 0 .or. a == b) cycle
      key = min(a, b)*key_base + max(a, b)
      slot = hash_slot(edge_hash, key)
      edge_hash%key(slot) = key
      line_slot(j) = slot
      on_line(a) = .true.
      on_line(b) = .true.
    end do

    ! how many cells have each of them, and the last one
    do c = 1, mesh%ncell
      nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
      do i = 1, nv
        a = mesh%cells(i, c)
        b = mesh%cells(modulo(i, nv) + 1, c)
        if (.not. (on_line(a) .and. on_line(b))) cycle
        key = min(a, b)*key_base + max(a, b)
        slot = hash_slot(edge_hash, key)
        if (edge_hash%key(slot) /= key) cycle
        edge_count(slot) = edge_count(slot) + 1
        edge_cell(slot) = c
        edge_local(slot) = i
      end do
    end do

    ! room for the curves' and the points' groups
    allocate (mesh%group(count(file_mesh%phys_dim(1:file_mesh%nphys) == 1 .or. file_mesh%phys_dim(1:file_mesh%nphys) == 0)))
    ngroup = 0
    do phys = 1, file_mesh%nphys
      if (file_mesh%phys_dim(phys) /= 1) cycle
      call names%add(' '//file_mesh%phys_name(phys)%s)
      names%n = len_trim(names%buf(1:names%n))
      nedge = 0
      ninner = 0
      do m = first(phys), first(phys + 1) - 1
        line = cand(members(m))
        if (line_slot(members(m)) < 0) cycle
        slot = line_slot(members(m))
        if (seen_group(slot) == phys) then      ! the same edge twice: its load would count twice
          call err%set(ERR_INPUT, 'elements '//i2s(file_mesh%line_tag(seen_line(slot)))//' and '// &
                       i2s(file_mesh%line_tag(line))//" of physical curve '"//file_mesh%phys_name(phys)%s// &
                       "' are the same edge (nodes "//i2s(mesh%node_tag(body_node(file_mesh%line_node(1, line))))// &
                       ' and '//i2s(mesh%node_tag(body_node(file_mesh%line_node(2, line))))// &
                       '): a line listed twice would apply its load twice')
          return
        end if
        seen_group(slot) = phys
        seen_line(slot) = line
        if (edge_count(slot) == 0) then           ! both nodes in the body, but no cell has that edge
          call err%set(ERR_INPUT, 'element '//i2s(file_mesh%line_tag(line))//" of physical curve '"// &
                       file_mesh%phys_name(phys)%s//"' joins nodes "// &
                       i2s(mesh%node_tag(body_node(file_mesh%line_node(1, line))))//' and '// &
                       i2s(mesh%node_tag(body_node(file_mesh%line_node(2, line))))// &
                       ', which are not an edge of any cell of the body: its condition or load would be lost')
          return
        end if
        if (edge_count(slot) > 1) then            ! inside the body: its nodes, once each
          do i = 1, 2
            a = body_node(file_mesh%line_node(i, line))
            if (marked(a)) cycle
            marked(a) = .true.
            ninner = ninner + 1
            inner(ninner) = a
          end do
          cycle
        end if
        c = edge_cell(slot)
        nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
        nedge = nedge + 1
        edges(:, nedge) = [mesh%cells(edge_local(slot), c), mesh%cells(modulo(edge_local(slot), nv) + 1, c)]
        cells(nedge) = c
      end do
      marked(inner(1:ninner)) = .false.
      if (nedge == 0 .and. ninner == 0) cycle
      ngroup = ngroup + 1
      mesh%group(ngroup)%name = file_mesh%phys_name(phys)%s
      mesh%group(ngroup)%nedge = nedge
      mesh%group(ngroup)%edge = edges(:, 1:nedge)
      mesh%group(ngroup)%cell = cells(1:nedge)
      mesh%group(ngroup)%nnode = ninner
      mesh%group(ngroup)%node = inner(1:ninner)
    end do
    call names%get(mesh%file_groups)
    mesh%file_groups = trim(adjustl(mesh%file_groups))
    mesh%ngroup = ngroup
  end subroutine boundary_groups

  !> One node group per physical point with nodes in the body, after the edge groups (a
  !! physical point named as a physical curve adds its nodes to the curve's group); the
  !! points' names go to file_groups. A point's node is the body's if the body's cells have
  !! it; a node in no cell of the file is matched to the body's node at its place. The same
  !! for a volume mesh (its face groups, its cells the volume cells).
  subroutine point_groups(file_mesh, body_node, mesh, err)
    type(file_mesh_t), intent(in), target :: file_mesh
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(inout) :: err
    logical, allocatable :: in_cell(:), taken(:)
    integer, allocatable :: nodes(:)
    integer, allocatable, target :: own_first(:), own_members(:)
    integer, pointer :: first(:), members(:)
    integer :: phys, point, n, nfound, group, c, i, m, st
    type(error_t) :: mem
    real(wp) :: tol
    character(len=:), allocatable :: names
    type(text_buffer_t) :: list

    allocate (nodes(file_mesh%npoint), taken(mesh%nnode), stat=st)
    if (st == 0 .and. allocated(file_mesh%point_first)) then
      first => file_mesh%point_first
      members => file_mesh%point_members
    else if (st == 0) then
      call group_members(file_mesh, 0, file_mesh%point_entity(1:file_mesh%npoint), own_first, own_members, mem)
      if (mem%failed()) st = 1
      first => own_first
      members => own_members
    end if
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for the physical points')
      return
    end if
    taken = .false.
    tol = 1.0e-9_wp*max(mesh%width, mesh%height, mesh%depth)
    do phys = 1, file_mesh%nphys
      if (file_mesh%phys_dim(phys) /= 0) cycle
      call list%add(' '//file_mesh%phys_name(phys)%s)
      nfound = 0
      do m = first(phys), first(phys + 1) - 1
        point = members(m)
        n = body_node(file_mesh%point_node(point))
        if (n == 0) then
          if (.not. allocated(in_cell)) then
            allocate (in_cell(file_mesh%nnode))
            in_cell = .false.
            do c = 1, file_mesh%ncell
              do i = 1, size(file_mesh%cell_node, 1)
                if (file_mesh%cell_node(i, c) > 0) in_cell(file_mesh%cell_node(i, c)) = .true.
              end do
            end do
          end if
          if (.not. in_cell(file_mesh%point_node(point))) &
            n = node_at(mesh, file_mesh%node_xy(:, file_mesh%point_node(point)), tol)
        end if
        if (n == 0) cycle
        if (taken(n)) cycle
        taken(n) = .true.
        nfound = nfound + 1
        nodes(nfound) = n
      end do
      taken(nodes(1:nfound)) = .false.
      if (nfound == 0) cycle
      group = 0
      do c = 1, mesh%ngroup
        if (mesh%group(c)%name == file_mesh%phys_name(phys)%s) group = c
      end do
      if (group == 0) then
        mesh%ngroup = mesh%ngroup + 1
        group = mesh%ngroup
        mesh%group(group)%name = file_mesh%phys_name(phys)%s
        mesh%group(group)%point = .true.
        allocate (mesh%group(group)%edge(merge(2, 3, size(mesh%xy, 1) == 2), 0), mesh%group(group)%cell(0))
      end if
      if (.not. allocated(mesh%group(group)%node)) allocate (mesh%group(group)%node(0))
      mesh%group(group)%node = [mesh%group(group)%node, nodes(1:nfound)]
      mesh%group(group)%nnode = size(mesh%group(group)%node)
    end do
    call list%get(names)
    if (len(names) == 0) return
    if (len(mesh%file_groups) == 0) mesh%file_groups = '(none)'
    mesh%file_groups = mesh%file_groups//'; physical points:'//names
  end subroutine point_groups

  !> The body node within tol of xy (the nearest), 0 if none.
  integer function node_at(mesh, xy, tol) result(n)
    type(mesh_t), intent(in) :: mesh
    real(wp), intent(in) :: xy(:), tol
    real(wp) :: dist, best
    integer :: k
    n = 0
    best = tol
    do k = 1, mesh%nnode
      dist = maxval(abs(mesh%xy(:, k) - xy))
      if (dist <= best) then
        n = k
        best = dist
      end if
    end do
  end function node_at

  !> The physical group (dim, tag), 0 if the file has none.
  integer function phys_index(file_mesh, dim, tag) result(p)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: dim, tag
    integer :: slot
    integer(i8) :: key
    p = 0
    if (file_mesh%nphys == 0) return
    key = group_key(dim, tag)
    slot = hash_slot(file_mesh%phys_hash, key)
    if (file_mesh%phys_hash%key(slot) == key) p = file_mesh%phys_of_slot(slot)
  end function phys_index

  !> The items (lines or points, by their entities `item_entity`, 0: none) of every physical
  !! group of dimension `dim`: those of group p are members(first(p):first(p + 1) - 1), in
  !! file order, each once. One pass over the items, so many groups cost linear time.
  !! err (ERR_MEMORY): out of memory.
  subroutine group_members(file_mesh, dim, item_entity, first, members, err)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: dim, item_entity(:)
    integer, allocatable, intent(out) :: first(:), members(:)
    type(error_t), intent(out) :: err     !< ERR_MEMORY: no room for the lists
    integer, allocatable :: fill(:), last_item(:)
    integer :: pass, item, j, p, st
    allocate (first(file_mesh%nphys + 1), fill(file_mesh%nphys), last_item(file_mesh%nphys), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for the members of '//i2s(file_mesh%nphys)//' physical groups')
      return
    end if
    fill = 0
    do pass = 1, 2            ! count, then place
      last_item = 0
      do item = 1, size(item_entity)
        if (item_entity(item) == 0) cycle
        associate (phys => file_mesh%ent(item_entity(item))%phys)
          do j = 1, size(phys)
            p = phys_index(file_mesh, dim, phys(j))
            if (p == 0) cycle
            if (last_item(p) == item) cycle     ! a tag listed twice counts once
            last_item(p) = item
            fill(p) = fill(p) + 1
            if (pass == 2) members(first(p) + fill(p) - 1) = item
          end do
        end associate
      end do
      if (pass == 1) then
        first(1) = 1
        do p = 1, file_mesh%nphys
          first(p + 1) = first(p) + fill(p)
        end do
        allocate (members(first(file_mesh%nphys + 1) - 1), stat=st)
        if (st /= 0) then
          call err%set(ERR_MEMORY, 'not enough memory for the members of '//i2s(file_mesh%nphys)//' physical groups')
          return
        end if
        fill = 0
      end if
    end do
  end subroutine group_members

  !> Refuse cells that overlap across an edge: with every cell counter-clockwise, the two
  !! cells of an inner edge run along it in opposite directions, so an edge run twice in
  !! the same direction has two cells on one side (a node moved or swapped, or a wrong
  !! node in a cell; an edge shared by three cells too). The directed edges are bucketed
  !! by their first node (a counting sort in cell order); in a bucket, an edge whose end
  !! node was met before repeats. The message names the repeat met first in cell order.
  subroutine check_overlapping_cells(mesh, err)
    type(mesh_t), intent(in) :: mesh
    type(error_t), intent(inout) :: err
    ! seq: 4 (cell - 1) + the edge's place in the cell, increasing in cell order
    integer, allocatable :: first(:), edge_to(:), edge_seq(:), seen_from(:), seen_seq(:)
    integer :: c, i, nv, a, b, j, st, ne, dup_seq, dup_first
    ne = 0
    do c = 1, mesh%ncell
      ne = ne + merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
    end do
    allocate (first(mesh%nnode + 2), edge_to(ne), edge_seq(ne), seen_from(mesh%nnode), seen_seq(mesh%nnode), &
              stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to check '//i2s(mesh%ncell)//' cells for overlaps')
      return
    end if
    first = 0
    do c = 1, mesh%ncell
      nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
      do i = 1, nv
        a = mesh%cells(i, c)
        first(a + 2) = first(a + 2) + 1
      end do
    end do
    first(1) = 1
    do a = 1, mesh%nnode + 1
      first(a + 1) = first(a + 1) + first(a)
    end do
    do c = 1, mesh%ncell                            ! first(a + 1): the next free place of bucket a
      nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
      do i = 1, nv
        a = mesh%cells(i, c)
        j = first(a + 1)
        edge_to(j) = mesh%cells(modulo(i, nv) + 1, c)
        edge_seq(j) = 4*(c - 1) + i
        first(a + 1) = j + 1
      end do
    end do
    seen_from = 0
    dup_seq = huge(1)
    dup_first = 0
    do a = 1, mesh%nnode
      do j = first(a), first(a + 1) - 1
        b = edge_to(j)
        if (seen_from(b) == a) then
          if (edge_seq(j) < dup_seq) then
            dup_seq = edge_seq(j)
            dup_first = seen_seq(b)
          end if
          exit
        end if
        seen_from(b) = a
        seen_seq(b) = edge_seq(j)
      end do
    end do
    if (dup_first == 0) return
    c = (dup_seq - 1)/4 + 1
    i = dup_seq - 4*(c - 1)
    nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
    a = mesh%cells(i, c)
    b = mesh%cells(modulo(i, nv) + 1, c)
    call err%set(ERR_INPUT, 'elements '//i2s(mesh%cell_tag((dup_first - 1)/4 + 1))//' and '// &
                 i2s(mesh%cell_tag(c))//' overlap: both lie on the same side of their edge from node '// &
                 i2s(mesh%node_tag(a))//' to node '//i2s(mesh%node_tag(b))// &
                 ' (a node misplaced or a wrong node in a cell)')
  end subroutine check_overlapping_cells

  !> Refuse two cells with the same nodes (in any order): a cell listed twice would count
  !! its stiffness twice. The cells are bucketed by their largest node (a counting sort, in
  !! cell order), so duplicates share a bucket; a bucket is searched pair by pair, a large
  !! one sorted. The message names the first two cells of the smallest duplicated node list
  !! (the lists compared as sorted tuples).
  subroutine check_duplicate_cells(mesh, err)
    type(mesh_t), intent(in) :: mesh
    type(error_t), intent(inout) :: err
    integer, parameter :: PAIRWISE = 32            ! larger buckets are sorted
    integer, allocatable :: key(:, :), first(:), members(:)
    integer :: c, n, st, i, j, k, b, lo, hi, best_i, best_j
    n = mesh%ncell
    if (n < 2) return
    allocate (key(4, n), first(mesh%nnode + 2), members(n), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to check '//i2s(n)//' cells for duplicates')
      return
    end if
    key = 0
    first = 0
    do c = 1, n
      key(1:mesh%nvert, c) = mesh%cells(:, c)       ! a triangle's 4th node is 0 (or absent)
      call sort4(key(:, c))
      first(key(4, c) + 2) = first(key(4, c) + 2) + 1
    end do
    first(1) = 1
    do k = 1, mesh%nnode + 1
      first(k + 1) = first(k + 1) + first(k)
    end do
    do c = 1, n                                     ! first(b + 1): the next free place of bucket b
      b = key(4, c)
      members(first(b + 1)) = c
      first(b + 1) = first(b + 1) + 1
    end do
    best_i = 0
    best_j = 0
    do b = 1, mesh%nnode
      lo = first(b)
      hi = first(b + 1) - 1
      if (hi - lo + 1 > PAIRWISE) then
        call merge_sort_by_keys(members(lo:hi), key)
        do i = lo, hi - 1
          if (all(key(:, members(i)) == key(:, members(i + 1)))) then
            call keep(members(i), members(i + 1))
            exit
          end if
        end do
        cycle
      end if
      do i = lo, hi - 1
        do j = i + 1, hi
          if (all(key(:, members(i)) == key(:, members(j)))) then
            call keep(members(i), members(j))
            exit
          end if
        end do
      end do
    end do
    if (best_i > 0) call err%set(ERR_INPUT, 'elements '//i2s(mesh%cell_tag(best_i))//' and '// &
                                 i2s(mesh%cell_tag(best_j))//' have the same nodes: a cell listed twice would '// &
                                 'count its stiffness twice')
  contains
    !> Sort four integers in place (a sorting network: the two pairs, then their
    !! smaller and larger ends, then the middle two).
    pure subroutine sort4(v)
      integer, intent(inout) :: v(4)
      integer :: lo1, hi1, lo2, hi2, mid1, mid2
      lo1 = min(v(1), v(2))
      hi1 = max(v(1), v(2))
      lo2 = min(v(3), v(4))
      hi2 = max(v(3), v(4))
      mid1 = max(lo1, lo2)
      mid2 = min(hi1, hi2)
      v(1) = min(lo1, lo2)
      v(2) = min(mid1, mid2)
      v(3) = max(mid1, mid2)
      v(4) = max(hi1, hi2)
    end subroutine sort4
    !> Keep the duplicate pair (ci, cj), ci < cj the first two of their list, if its node
    !! list is the smallest so far.
    subroutine keep(ci, cj)
      integer, intent(in) :: ci, cj
      integer :: m
      if (best_i > 0) then
        do m = 1, 4
          if (key(m, ci) /= key(m, best_i)) exit
        end do
        if (m > 4) return
        if (key(m, ci) > key(m, best_i)) return
      end if
      best_i = ci
      best_j = cj
    end subroutine keep
  end subroutine check_duplicate_cells

  !> A body is one connected piece of cells (cells connected through shared nodes): its rigid
  !! motions, supports and floating checks are those of one body. Two pieces in one region
  !! (a region drawn as two parts, or a cell whose node numbers were corrupted into another
  !! part) are bad input naming one cell of each.
  subroutine check_one_piece(mesh, err)
    type(mesh_t), intent(in) :: mesh
    type(error_t), intent(inout) :: err
    integer, allocatable :: parent(:)
    integer :: c, i, nv, r, root, other, st
    if (mesh%ncell < 2) return
    allocate (parent(mesh%nnode), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to check that the cells form one piece')
      return
    end if
    parent = [(i, i=1, mesh%nnode)]
    do c = 1, mesh%ncell
      nv = shape_vertices(mesh%cell_type(c))
      root = find(mesh%cells(1, c))
      do i = 2, nv
        r = find(mesh%cells(i, c))
        if (r /= root) parent(r) = root
      end do
    end do
    root = find(mesh%cells(1, 1))
    do c = 2, mesh%ncell
      if (find(mesh%cells(1, c)) == root) cycle
      other = c
      call err%set(ERR_INPUT, 'its cells form more than one piece (element '//i2s(mesh%cell_tag(1))// &
                   ' and element '//i2s(mesh%cell_tag(other))//' share no chain of nodes): a body is one '// &
                   'connected piece; give each piece its own physical '// &
                   trim(merge('surface', 'volume ', size(mesh%xy, 1) == 2))//' and &body')
      return
    end do
  contains
    !> The root of node k's piece, halving the path on the way.
    integer function find(k)
      integer, intent(in) :: k
      find = k
      do while (parent(find) /= find)
        parent(find) = parent(parent(find))
        find = parent(find)
      end do
    end function find
  end subroutine check_one_piece

  !> The file's nodes of a body's cells (`file_cell`, each of up to nvert nodes, 0 = none) in
  !! increasing tag order (`order`), and `body_node` (file_mesh%nnode) marking them (1) and
  !! every other node 0. A body that is a small part of the file gathers its nodes from its
  !! cells (the same set, the same order once sorted by tag, as a pass over all the file's nodes).
  subroutine body_file_nodes(file_mesh, file_cell, nvert, body_node, order, err)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: file_cell(:)            !< the body's cells in the file
    integer, intent(in) :: nvert                   !< nodes per cell row of file_mesh%cell_node
    integer, allocatable, intent(out) :: body_node(:), order(:)
    type(error_t), intent(out) :: err
    integer :: k, c, i, nnew, st, ncell
    ncell = size(file_cell)
    allocate (body_node(file_mesh%nnode), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for '//i2s(file_mesh%nnode)//' nodes')
      return
    end if
    body_node = 0
    if (int(nvert, i8)*int(ncell, i8) < file_mesh%nnode/8) then
      allocate (order(nvert*ncell))
      nnew = 0
      do k = 1, ncell
        do c = 1, nvert
          i = file_mesh%cell_node(c, file_cell(k))
          if (i == 0) cycle
          if (body_node(i) /= 0) cycle
          body_node(i) = 1
          nnew = nnew + 1
          order(nnew) = i
        end do
      end do
      order = order(1:nnew)
    else
      do k = 1, ncell
        do c = 1, nvert
          if (file_mesh%cell_node(c, file_cell(k)) > 0) body_node(file_mesh%cell_node(c, file_cell(k))) = 1
        end do
      end do
      order = pack([(k, k=1, file_mesh%nnode)], body_node > 0)
    end if
    call sort_by_tag(order, file_mesh%node_tag)
  end subroutine body_file_nodes

  !> Sort the file node indices `idx` by increasing tag (bottom-up merge sort).
  subroutine sort_by_tag(idx, tag)
    integer, intent(inout) :: idx(:)
    integer, intent(in) :: tag(:)
    integer :: n
    n = size(idx)
    if (n < 2) return
    if (all(tag(idx(2:n)) > tag(idx(1:n - 1)))) return     ! the usual case: already sorted
    call merge_sort_by_keys(idx, reshape(tag, [1, size(tag)]))
  end subroutine sort_by_tag

end module mesh_topology
