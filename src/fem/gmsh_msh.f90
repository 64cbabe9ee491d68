!> The Gmsh MSH 4.1 ASCII reader: one body's mesh (module mesh, type mesh_t) from the
!! triangles and quadrangles of a physical surface, with the boundary edges of every
!! physical curve and the nodes of every physical point as named groups. In a 3D run
!! (space's NDIM = 3) from the tetrahedra and hexahedra of a physical volume, with the
!! boundary faces of every physical surface as face groups and the nodes of every physical
!! curve and point as node groups (module volume_topology).
!!
!! The file is read whole into memory and scanned once, token by token (module
!! text_scanner: a 500k-node mesh, 4 million numbers, in about 1 s; peak memory about 2.8
!! times the file). Its sections fill a file_mesh_t (module mesh_topology), which then
!! gives the body. Node tags are looked up in an array indexed by tag when they are dense,
!! through a hash table otherwise, so tags may be sparse and unordered. Gmsh gives a point
!! that bounds or is embedded in a meshed surface the node of the surface's mesh.
!!
!! Every count that sizes an allocation is read by read_count (module text_scanner), the
!! one place for checks of counts against the file: each is checked, in 64-bit arithmetic,
!! against the characters left in the file (an item takes at least a few of them) before
!! anything is allocated. Tags must be >= 1, as the format says.
!!
!! Errors: an error_t, ERR_INPUT for bad input (the message names the body, the file and
!! the line or element tag), ERR_MEMORY otherwise. Only first-order elements (2-node
!! lines, 3-node triangles, 4-node quadrangles, points) in the plane z = 0 are read; in a 3D
!! run also 4-node tetrahedra and 8-node hexahedra, anywhere in space.
module gmsh_msh
  use kinds, only: wp, i8
  use space, only: NDIM
  use errors, only: error_t, ERR_INPUT, ERR_MEMORY
  use strings, only: i2s
  use digest, only: text_digest
  use int_hash, only: int_hash_t, hash_init, hash_slot, HASH_EMPTY
  use text_scanner, only: scanner_t, scanner_load, scan_fail, next_token, get_int, get_real, read_count, &
                          expect, skip_past, bytes_left
  use mesh, only: mesh_t
  use mesh_topology, only: file_mesh_t, body_from_file, add_physical, index_entities, entity_index, index_groups
  use volume_topology, only: body_from_volumes
  implicit none (type, external)
  private

  public :: msh_read, msh_read_shared

  !> Node tag -> file node number, while the elements are read: an array indexed by tag
  !! when the tags $Nodes announces are dense (Gmsh writes 1..N), else a hash table. A tag
  !! outside the announced range moves the index to the hash table.
  type :: node_index_t
    logical :: direct = .false.                ! node_of_tag holds the index
    integer :: lo = 1, hi = 0                  ! the range of node_of_tag
    integer, allocatable :: node_of_tag(:)     ! (lo:hi) the node of each tag, 0: none
    type(int_hash_t) :: hash                   ! the tags, when not direct
    integer, allocatable :: node_of_slot(:)    ! (0:hash%mask) the node of each tag's slot
  end type node_index_t

  ! the direct index is used when the announced tag range is at most this many times the node count
  integer, parameter :: DIRECT_SPAN = 4

contains

  !> Read one body of a Gmsh MSH 4.1 ASCII file into `mesh`.
  !!
  !! The body is the triangles and quadrangles of the physical surface named `region`; with
  !! region = '' the file may hold at most one physical surface, and a file without physical
  !! groups gives every 2D element. `mesh` gets the body's nodes and cells numbered for
  !! locality (`node_tag` keeps the tag; `file_node` and `file_cell` the file's order:
  !! the nodes by increasing tag), its cells counter-clockwise (`cell_tag`,
  !! `cell_type`), element = ELEM_Q1, ELEM_P1 or ELEM_MIXED, the bounding box, one edge
  !! group per physical curve with edges on the body's boundary, then one node group per
  !! physical point with nodes of the body (`file_groups` lists every physical curve and
  !! point name of the file). In a 3D run (NDIM = 3) the body is the tetrahedra and
  !! hexahedra of the physical volume `region` (volume_topology's body_from_volumes).
  subroutine msh_read(path, region, body_id, mesh, err, hex)
    character(len=*), intent(in) :: path     !< the .msh file
    character(len=*), intent(in) :: region   !< physical surface name of the body, or ''
    integer, intent(in) :: body_id           !< the body's number, for messages
    type(mesh_t), intent(out) :: mesh        !< the body's mesh
    type(error_t), intent(out) :: err        !< ERR_INPUT (bad file) or ERR_MEMORY, one sentence
    character(len=16), intent(out), optional :: hex  !< the content hash of the bytes read ('' if none)
    type(scanner_t) :: scanner
    type(file_mesh_t) :: file_mesh

    allocate (file_mesh%phys_dim(8), file_mesh%phys_tag(8), file_mesh%phys_name(8))
    call scanner_load(scanner, path)
    if (present(hex)) then
      hex = ''
      if (.not. scanner%err%failed()) hex = text_digest(scanner%text)
    end if
    if (.not. scanner%err%failed()) call parse(scanner, file_mesh)
    if (.not. scanner%err%failed()) call build(scanner, file_mesh, trim(region), mesh)
    if (allocated(scanner%text)) deallocate (scanner%text)
    call outcome(scanner, path, body_id, mesh, err)
  end subroutine msh_read

  !> Several bodies from one .msh file (the same path for all): the file is read and parsed
  !! once, then each body is built from it (the bodies in parallel on `nthr` threads).
  !! Arguments as msh_read's, one per body.
  subroutine msh_read_shared(path, region, ids, mesh, err, nthr, hex)
    character(len=*), intent(in) :: path          !< the .msh file of these bodies
    character(len=*), intent(in) :: region(:)     !< physical surface name of each body
    integer, intent(in) :: ids(:)                 !< each body's id (messages)
    type(mesh_t), intent(inout) :: mesh(:)        !< the bodies' meshes
    type(error_t), intent(out) :: err(:)          !< each body's error, as msh_read's
    integer, intent(in) :: nthr                   !< threads for the builds
    character(len=16), intent(out), optional :: hex  !< the content hash of the bytes read ('' if none)
    type(scanner_t) :: scanner
    type(scanner_t), allocatable :: body_scanner(:)
    type(file_mesh_t) :: file_mesh
    integer :: a, n
    logical :: loaded

    n = size(region)
    allocate (file_mesh%phys_dim(8), file_mesh%phys_tag(8), file_mesh%phys_name(8), body_scanner(n))
    call scanner_load(scanner, path)
    loaded = .not. scanner%err%failed()
    if (present(hex)) hex = ''
    ! the content hash (which a checkpoint records) of the same bytes, beside the parse
    ! (which changes the scanner's position and status, never its text)
    !$omp parallel sections num_threads(min(2, nthr)) if (loaded .and. present(hex))
    !$omp section
    if (loaded) call parse(scanner, file_mesh)
    if (.not. scanner%err%failed()) call index_groups(file_mesh)     ! once for all the bodies
    !$omp section
    if (loaded .and. present(hex)) hex = text_digest(scanner%text)
    !$omp end parallel sections
    if (allocated(scanner%text)) deallocate (scanner%text)
    do a = 1, n
      body_scanner(a) = scanner
    end do
    !$omp parallel do num_threads(nthr) schedule(dynamic, 1)
    do a = 1, n
      if (.not. body_scanner(a)%err%failed()) call build(body_scanner(a), file_mesh, trim(region(a)), mesh(a))
    end do
    !$omp end parallel do
    do a = 1, n
      call outcome(body_scanner(a), path, ids(a), mesh(a), err(a))
    end do
  end subroutine msh_read_shared

  !> The status of a read: on failure, one sentence naming the body, the file and the line,
  !! and an empty mesh.
  subroutine outcome(scanner, path, body_id, mesh, err)
    type(scanner_t), intent(in) :: scanner
    character(len=*), intent(in) :: path
    integer, intent(in) :: body_id
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(out) :: err
    character(len=:), allocatable :: msg
    if (.not. scanner%err%failed()) return
    msg = 'body '//i2s(body_id)//": mesh file '"//path//"'"
    if (scanner%err_line > 0) msg = msg//', line '//i2s(scanner%err_line)
    msg = msg//': '//scanner%err%message//'.'
    call err%set(scanner%err%category, msg)
    mesh%nnode = 0
    mesh%ncell = 0
  end subroutine outcome

  !> Build the body from the parsed file; a failure is recorded in the scanner (no line).
  subroutine build(scanner, file_mesh, region, mesh)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(in) :: file_mesh
    character(len=*), intent(in) :: region
    type(mesh_t), intent(inout) :: mesh
    type(error_t) :: err
    if (NDIM == 3) then
      call body_from_volumes(file_mesh, region, scanner%path, mesh, err)
    else
      call body_from_file(file_mesh, region, scanner%path, mesh, err)
    end if
    if (.not. err%failed()) return
    ! err%message, not err%text(): the bodies of one file are built on several threads, and
    ! gfortran 12 keeps the length of a deferred-length character function result in a
    ! static variable of its call site, which two threads running this line share (the
    ! reason came out empty in about 2% of two-thread runs with two failing bodies)
    if (.not. allocated(err%message)) err%message = 'cannot be built'
    call scan_fail(scanner, err%message, merge(ERR_MEMORY, ERR_INPUT, err%category == ERR_MEMORY), .false.)
  end subroutine build

  ! ---- parsing ----------------------------------------------------------------------------

  !> Read every section of the file into file_mesh.
  subroutine parse(scanner, file_mesh)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    integer(i8) :: s, e
    character(len=:), allocatable :: tok
    type(node_index_t) :: by_tag
    logical :: has_format, has_nodes, has_elements

    has_format = .false.
    has_nodes = .false.
    has_elements = .false.
    do
      call next_token(scanner, s, e)
      if (s > scanner%n) exit
      tok = scanner%text(s:e)
      if (.not. has_format .and. tok /= '$MeshFormat') then
        call scan_fail(scanner, "does not start with $MeshFormat (found '"//tok(1:min(len(tok), 40))// &
                  "'): not a Gmsh MSH file")
        return
      end if
      scanner%section = tok
      if ((tok == '$Entities' .and. allocated(file_mesh%ent)) .or. (tok == '$Nodes' .and. has_nodes) .or. &
          (tok == '$Elements' .and. has_elements) .or. (tok == '$MeshFormat' .and. has_format)) then
        call scan_fail(scanner, 'has a second '//tok//' section')
        return
      end if
      select case (tok)
      case ('$MeshFormat')
        call read_format(scanner)
        has_format = .true.
      case ('$PhysicalNames')
        call read_physical_names(scanner, file_mesh)
      case ('$Entities')
        call read_entities(scanner, file_mesh)
      case ('$Nodes')
        call read_nodes(scanner, file_mesh, by_tag)
        has_nodes = .true.
      case ('$Elements')
        if (.not. has_nodes) call scan_fail(scanner, '$Elements comes before $Nodes')
        if (NDIM == 3) then
          call read_elements_3d(scanner, file_mesh, by_tag)
        else
          call read_elements(scanner, file_mesh, by_tag)
        end if
        has_elements = .true.
      case default
        if (tok(1:1) /= '$' .or. len(tok) < 2) then
          call scan_fail(scanner, "expected a section such as $Nodes, found '"//tok(1:min(len(tok), 40))//"'")
        else if (index(tok, '$End') == 1) then
          call scan_fail(scanner, tok//' without its section')
        else
          call skip_past(scanner, '$End'//tok(2:))
        end if
      end select
      if (scanner%err%failed()) return
    end do
    if (.not. has_format) then
      call scan_fail(scanner, 'is empty: no $MeshFormat section')
    else if (.not. has_nodes) then
      call scan_fail(scanner, 'has no $Nodes section (truncated file?)')
    else if (.not. has_elements) then
      call scan_fail(scanner, 'has no $Elements section (truncated file?)')
    end if
  end subroutine parse

  !> $MeshFormat: version 4.1, ASCII.
  subroutine read_format(scanner)
    type(scanner_t), intent(inout) :: scanner
    integer(i8) :: s, e
    integer :: file_type, data_size
    call next_token(scanner, s, e)
    if (s > scanner%n) then
      call scan_fail(scanner, 'the file ends inside $MeshFormat (truncated file?)')
      return
    end if
    if (scanner%text(s:e) /= '4.1') then
      call scan_fail(scanner, 'is MSH version '//scanner%text(s:min(e, s + 20))//', and only MSH 4.1 is read; '// &
                'write version 4.1 with `gmsh -format msh41` or Mesh.MshFileVersion = 4.1')
      return
    end if
    file_type = get_int(scanner, 'the file type')
    if (.not. scanner%err%failed() .and. file_type /= 0) then
      call scan_fail(scanner, 'is a binary MSH file, and only ASCII is read; write it without -bin '// &
                '(Mesh.Binary = 0)')
      return
    end if
    data_size = get_int(scanner, 'the data size')
    call expect(scanner, '$EndMeshFormat')
  end subroutine read_format

  !> $PhysicalNames: dimension, tag and quoted name of each physical group (a name of any
  !! length, on one line).
  subroutine read_physical_names(scanner, file_mesh)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    integer :: n, k, dim, tag
    type(error_t) :: err
    integer(i8) :: q
    ! a name takes at least 7 characters: '1 2 ""' and a line end
    n = read_count(scanner, 'the number of physical names', 7, 'physical names')
    if (scanner%err%failed()) return
    do k = 1, n
      dim = get_int(scanner, 'a physical dimension')
      tag = get_int(scanner, 'a physical tag')
      if (scanner%err%failed()) return
      if (dim < 0 .or. dim > 3) then
        call scan_fail(scanner, 'physical group '//i2s(tag)//' has dimension '//i2s(dim)//', not 0, 1, 2 or 3')
        return
      end if
      ! the name: from the opening quote to the closing one on the same line
      do while (scanner%pos <= scanner%n)
        if (scanner%text(scanner%pos:scanner%pos) /= ' ' .and. scanner%text(scanner%pos:scanner%pos) /= achar(9)) exit
        scanner%pos = scanner%pos + 1
      end do
      if (scanner%pos > scanner%n) then
        call scan_fail(scanner, 'the file ends inside $PhysicalNames (truncated file?)')
        return
      end if
      q = 0
      if (scanner%text(scanner%pos:scanner%pos) == '"') &
        q = scan(scanner%text(scanner%pos + 1:scanner%n), '"'//achar(10), kind=i8)
      if (q == 0) then
        call scan_fail(scanner, 'a physical name must be in double quotes on one line')
        return
      end if
      if (scanner%text(scanner%pos + q:scanner%pos + q) /= '"') then
        call scan_fail(scanner, 'a physical name must be in double quotes on one line')
        return
      end if
      call add_physical(file_mesh, dim, tag, scanner%text(scanner%pos + 1:scanner%pos + q - 1), err)
      if (err%failed()) then
        call scan_fail(scanner, 'not enough memory for '//i2s(k)//' physical groups', ERR_MEMORY)
        return
      end if
      scanner%pos = scanner%pos + q + 1
    end do
    call expect(scanner, '$EndPhysicalNames')
  end subroutine read_physical_names

  !> $Entities: the physical tags of every point, curve and surface (volumes skipped, but
  !! in a 3D run).
  subroutine read_entities(scanner, file_mesh)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    ! the fewest characters of a point (tag, x, y, z, no physical tag) and of a curve,
    ! surface or volume (tag, a box of 6, no physical tag, no bounding entity)
    integer, parameter :: POINT_BYTES = 10, OTHER_BYTES = 18
    character(len=*), parameter :: KIND(0:3) = ['points  ', 'curves  ', 'surfaces', 'volumes ']
    integer :: nents(0:3), dim, k, j, nb, tag, np, bound, st, nkeep
    integer(i8) :: need
    type(error_t) :: err
    real(wp) :: r
    integer, allocatable :: phys(:)
    do dim = 0, 3
      nents(dim) = read_count(scanner, 'the number of '//trim(KIND(dim)), merge(POINT_BYTES, OTHER_BYTES, dim == 0), &
                              trim(KIND(dim)))
    end do
    if (scanner%err%failed()) return
    need = POINT_BYTES*int(nents(0), i8) + OTHER_BYTES*(int(nents(1), i8) + nents(2) + nents(3))
    if (need > bytes_left(scanner)) then
      call scan_fail(scanner, '$Entities announces '//i2s(nents(0))//' points, '//i2s(nents(1))//' curves, '// &
                     i2s(nents(2))//' surfaces and '//i2s(nents(3))//' volumes, but the rest of the file '// &
                     'is too short for them')
      return
    end if
    nkeep = nents(0) + nents(1) + nents(2)
    if (NDIM == 3) nkeep = nkeep + nents(3)     ! the volumes are read, and kept in a 3D run
    allocate (file_mesh%ent(nkeep), stat=st)
    if (st /= 0) then
      call scan_fail(scanner, 'not enough memory for '//i2s(nkeep)//' entities', ERR_MEMORY)
      return
    end if
    do dim = 0, 3
      do k = 1, nents(dim)
        tag = get_int(scanner, 'an entity tag')
        do j = 1, merge(3, 6, dim == 0)
          r = get_real(scanner, 'an entity coordinate')
        end do
        np = read_count(scanner, 'the number of physical tags', 2, &
                        'physical tags for '//KIND(dim)(1:len_trim(KIND(dim)) - 1)//' '//i2s(tag))
        if (scanner%err%failed()) return
        allocate (phys(np), stat=st)
        if (st /= 0) then
          call scan_fail(scanner, 'not enough memory for '//i2s(np)//' physical tags', ERR_MEMORY)
          return
        end if
        do j = 1, np     ! negative when the entity is reversed in the group
          phys(j) = abs(get_int(scanner, 'a physical tag'))
        end do
        if (dim > 0) then
          nb = read_count(scanner, 'the number of bounding entities', 2, &
                          'bounding entities for '//KIND(dim)(1:len_trim(KIND(dim)) - 1)//' '//i2s(tag))
          do j = 1, nb
            bound = get_int(scanner, 'a bounding entity tag')
          end do
        end if
        if (scanner%err%failed()) return
        if (dim <= 2 .or. NDIM == 3) then
          file_mesh%nent = file_mesh%nent + 1
          file_mesh%ent(file_mesh%nent)%dim = dim
          file_mesh%ent(file_mesh%nent)%tag = tag
          call move_alloc(phys, file_mesh%ent(file_mesh%nent)%phys)
          do j = 1, np        ! physical groups without a name are named by their tag
            call add_physical(file_mesh, dim, file_mesh%ent(file_mesh%nent)%phys(j), &
                              i2s(file_mesh%ent(file_mesh%nent)%phys(j)), err)
            if (err%failed()) then
              call scan_fail(scanner, err%message, ERR_MEMORY)
              return
            end if
          end do
        else
          deallocate (phys)
        end if
      end do
    end do
    call index_entities(file_mesh, err)
    if (err%failed()) then
      call scan_fail(scanner, err%message, ERR_MEMORY)
      return
    end if
    call expect(scanner, '$EndEntities')
  end subroutine read_entities

  !> $Nodes: blocks of tags then coordinates; z must be 0 (but in a 3D run).
  subroutine read_nodes(scanner, file_mesh, by_tag)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    type(node_index_t), intent(inout) :: by_tag
    ! the fewest characters of a node (tag and x, y, z) and of a block's header
    integer, parameter :: NODE_BYTES = 8, BLOCK_BYTES = 8
    integer :: nblock, ntotal, b, edim, etag, param, nb, k, j, st, slot, first, tag, tag_lo, tag_hi
    real(wp) :: z, r
    type(error_t) :: err

    nblock = read_count(scanner, 'the number of node blocks', BLOCK_BYTES, 'node blocks')
    ntotal = read_count(scanner, 'the number of nodes', NODE_BYTES, 'nodes')
    tag_lo = get_int(scanner, 'the smallest node tag')
    tag_hi = get_int(scanner, 'the largest node tag')
    if (scanner%err%failed()) return
    allocate (file_mesh%node_tag(ntotal), file_mesh%node_xy(merge(3, 2, NDIM == 3), ntotal), stat=st)
    by_tag%direct = tag_lo >= 1 .and. tag_hi >= tag_lo .and. &
                    int(tag_hi, i8) - tag_lo + 1 <= DIRECT_SPAN*(int(ntotal, i8) + 1)
    if (by_tag%direct) then
      by_tag%lo = tag_lo
      by_tag%hi = tag_hi
      if (st == 0) allocate (by_tag%node_of_tag(tag_lo:tag_hi), source=0, stat=st)
    else
      if (st == 0) call index_to_hash(by_tag, file_mesh%node_tag, 0, ntotal, err)
    end if
    if (st /= 0 .or. err%failed()) then
      call scan_fail(scanner, 'not enough memory for '//i2s(ntotal)//' nodes', ERR_MEMORY)
      return
    end if
    file_mesh%nnode = 0
    do b = 1, nblock
      edim = get_int(scanner, 'an entity dimension')
      etag = get_int(scanner, 'an entity tag')
      param = get_int(scanner, 'the parametric flag')
      nb = read_count(scanner, 'the number of nodes in the block', NODE_BYTES, 'nodes in a block')
      if (scanner%err%failed()) return
      if (int(file_mesh%nnode, i8) + nb > ntotal) then
        call scan_fail(scanner, 'the node blocks hold more nodes than the '//i2s(ntotal)//' announced')
        return
      end if
      first = file_mesh%nnode
      do k = first + 1, first + nb
        file_mesh%node_tag(k) = get_int(scanner, 'a node tag')
        if (scanner%err%failed()) return
        if (file_mesh%node_tag(k) < 1) then
          call scan_fail(scanner, 'node tag '//i2s(file_mesh%node_tag(k))//' in $Nodes: tags must be >= 1')
          return
        end if
        tag = file_mesh%node_tag(k)
        if (by_tag%direct .and. (tag < by_tag%lo .or. tag > by_tag%hi)) then
          call index_to_hash(by_tag, file_mesh%node_tag, k - 1, ntotal, err)
          if (err%failed()) then
            call scan_fail(scanner, err%message, ERR_MEMORY)
            return
          end if
        end if
        if (node_of(by_tag, tag) /= 0) then
          call scan_fail(scanner, 'node tag '//i2s(tag)//' appears twice')
          return
        end if
        if (by_tag%direct) then
          by_tag%node_of_tag(tag) = k
        else
          slot = hash_slot(by_tag%hash, int(tag, i8))
          by_tag%hash%key(slot) = tag
          by_tag%node_of_slot(slot) = k
        end if
      end do
      do k = first + 1, first + nb
        file_mesh%node_xy(1, k) = get_real(scanner, 'a node x coordinate')
        file_mesh%node_xy(2, k) = get_real(scanner, 'a node y coordinate')
        z = get_real(scanner, 'a node z coordinate')
        if (param /= 0) then
          do j = 1, edim
            r = get_real(scanner, 'a parametric coordinate')
          end do
        end if
        if (scanner%err%failed()) return
        if (NDIM == 3) then
          file_mesh%node_xy(3, k) = z
        else if (z /= 0.0_wp) then
          call scan_fail(scanner, 'node '//i2s(file_mesh%node_tag(k))//' has z = '//trim(real_text(z))// &
                    '; only 2D meshes in the plane z = 0 are read (this is a 3D mesh: a 3D deck, &scene '// &
                    'dimension=3, reads it)')
          return
        end if
      end do
      file_mesh%nnode = first + nb
    end do
    if (file_mesh%nnode /= ntotal) then
      call scan_fail(scanner, 'the node blocks hold '//i2s(file_mesh%nnode)//' nodes, not the '//i2s(ntotal)// &
                     ' announced')
      return
    end if
    call expect(scanner, '$EndNodes')
  end subroutine read_nodes

  !> $Elements: triangles and quadrangles (surface entities), lines (curve entities), points.
  subroutine read_elements(scanner, file_mesh, by_tag)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    type(node_index_t), intent(in) :: by_tag
    ! the fewest characters of an element (a point: tag and node) and of a block's header
    integer, parameter :: ELEMENT_BYTES = 4, BLOCK_BYTES = 8
    integer :: nblock, ntotal, b, edim, etag, etype, nb, k, j, nv, tag, ntg, ent, st, t, node

    nblock = read_count(scanner, 'the number of element blocks', BLOCK_BYTES, 'element blocks')
    ntotal = read_count(scanner, 'the number of elements', ELEMENT_BYTES, 'elements')
    k = get_int(scanner, 'the smallest element tag')
    k = get_int(scanner, 'the largest element tag')
    if (scanner%err%failed()) return
    ! sized for the worst case; the lines are a small part of a 2D mesh but bounded by ntotal too
    allocate (file_mesh%cell_tag(ntotal), file_mesh%cell_entity(ntotal), file_mesh%cell_node(4, ntotal), &
              file_mesh%line_tag(ntotal), file_mesh%line_entity(ntotal), file_mesh%line_node(2, ntotal), &
              file_mesh%point_entity(ntotal), file_mesh%point_node(ntotal), stat=st)
    if (st /= 0) then
      call scan_fail(scanner, 'not enough memory for '//i2s(ntotal)//' elements', ERR_MEMORY)
      return
    end if
    t = 0
    do b = 1, nblock
      edim = get_int(scanner, 'an entity dimension')
      etag = get_int(scanner, 'an entity tag')
      etype = get_int(scanner, 'an element type')
      select case (etype)
      case (1)
        nv = 2
      case (2)
        nv = 3
      case (3)
        nv = 4
      case (15)
        nv = 1
      case default
        nv = 1
      end select
      ! an element takes at least its tag and nodes, each a digit and a separator
      nb = read_count(scanner, 'the number of elements in the block', 2*(nv + 1), 'elements in a block')
      if (scanner%err%failed()) return
      if (int(t, i8) + nb > ntotal) then
        call scan_fail(scanner, 'the element blocks hold more elements than the '//i2s(ntotal)//' announced')
        return
      end if
      t = t + nb
      if (edim == 3) then
        call scan_fail(scanner, 'has elements of type '//i2s(etype)//' on volume '//i2s(etag)// &
                  ': a 3D mesh, and a 2D deck reads only 2D meshes (a 3D deck, &scene dimension=3, reads it)')
        return
      end if
      if (all(etype /= [1, 2, 3, 15])) then
        call scan_fail(scanner, unsupported_type(etype))
        return
      end if
      ent = entity_index(file_mesh, edim, etag)
      do k = 1, nb
        tag = get_int(scanner, 'an element tag')
        if (scanner%err%failed()) return
        if (tag < 1) then
          call scan_fail(scanner, 'element tag '//i2s(tag)//' in $Elements: tags must be >= 1')
          return
        end if
        if (etype == 1) then
          file_mesh%nline = file_mesh%nline + 1
          file_mesh%line_tag(file_mesh%nline) = tag
          file_mesh%line_entity(file_mesh%nline) = ent
        else if (etype == 15) then
          file_mesh%npoint = file_mesh%npoint + 1
          file_mesh%point_entity(file_mesh%npoint) = ent
        else
          file_mesh%ncell = file_mesh%ncell + 1
          file_mesh%cell_tag(file_mesh%ncell) = tag
          file_mesh%cell_entity(file_mesh%ncell) = ent
          file_mesh%cell_node(:, file_mesh%ncell) = 0
        end if
        do j = 1, nv
          ntg = get_int(scanner, 'a node tag')
          if (scanner%err%failed()) return
          if (ntg < 1) then
            call scan_fail(scanner, 'element '//i2s(tag)//' refers to node tag '//i2s(ntg)//': tags must be >= 1')
            return
          end if
          node = node_of(by_tag, ntg)
          if (node == 0) then
            call scan_fail(scanner, 'element '//i2s(tag)//' refers to node '//i2s(ntg)//', which is not in $Nodes')
            return
          end if
          if (etype == 1) then
            file_mesh%line_node(j, file_mesh%nline) = node
          else if (etype == 15) then
            file_mesh%point_node(file_mesh%npoint) = node
          else
            file_mesh%cell_node(j, file_mesh%ncell) = node
          end if
        end do
      end do
    end do
    if (t /= ntotal) then
      call scan_fail(scanner, 'the element blocks hold '//i2s(t)//' elements, not the '//i2s(ntotal)//' announced')
      return
    end if
    call expect(scanner, '$EndElements')
  end subroutine read_elements

  !> $Elements in a 3D run: tetrahedra and hexahedra (volume entities, the cells),
  !! triangles and quadrangles (surface entities, the faces), lines (curve entities),
  !! points. Each kind's arrays grow by blocks (doubling), so a file of tetrahedra does not
  !! hold room for every element in every kind. A block's type must be of its entity's
  !! dimension.
  subroutine read_elements_3d(scanner, file_mesh, by_tag)
    type(scanner_t), intent(inout) :: scanner
    type(file_mesh_t), intent(inout) :: file_mesh
    type(node_index_t), intent(in) :: by_tag
    ! the fewest characters of an element (a point: tag and node) and of a block's header
    integer, parameter :: ELEMENT_BYTES = 4, BLOCK_BYTES = 8
    character(len=*), parameter :: WHAT(0:3) = ['a point      ', 'a line       ', 'a surface    ', 'a volume     ']
    integer :: nblock, ntotal, b, edim, etag, etype, nb, k, j, nv, tag, ntg, ent, t, dim, nodes(8)
    type(error_t) :: err

    nblock = read_count(scanner, 'the number of element blocks', BLOCK_BYTES, 'element blocks')
    ntotal = read_count(scanner, 'the number of elements', ELEMENT_BYTES, 'elements')
    k = get_int(scanner, 'the smallest element tag')
    k = get_int(scanner, 'the largest element tag')
    if (scanner%err%failed()) return
    allocate (file_mesh%cell_tag(0), file_mesh%cell_entity(0), file_mesh%cell_node(8, 0), &
              file_mesh%face_tag(0), file_mesh%face_entity(0), file_mesh%face_node(4, 0), &
              file_mesh%line_tag(0), file_mesh%line_entity(0), file_mesh%line_node(2, 0), &
              file_mesh%point_entity(0), file_mesh%point_node(0))
    t = 0
    do b = 1, nblock
      edim = get_int(scanner, 'an entity dimension')
      etag = get_int(scanner, 'an entity tag')
      etype = get_int(scanner, 'an element type')
      select case (etype)
      case (1)
        nv = 2
        dim = 1
      case (2)
        nv = 3
        dim = 2
      case (3)
        nv = 4
        dim = 2
      case (4)
        nv = 4
        dim = 3
      case (5)
        nv = 8
        dim = 3
      case default     ! 15, and the types refused below
        nv = 1
        dim = 0
      end select
      ! an element takes at least its tag and nodes, each a digit and a separator
      nb = read_count(scanner, 'the number of elements in the block', 2*(nv + 1), 'elements in a block')
      if (scanner%err%failed()) return
      if (int(t, i8) + nb > ntotal) then
        call scan_fail(scanner, 'the element blocks hold more elements than the '//i2s(ntotal)//' announced')
        return
      end if
      t = t + nb
      if (all(etype /= [1, 2, 3, 4, 5, 15])) then
        call scan_fail(scanner, unsupported_type_3d(etype))
        return
      end if
      if (edim /= dim) then
        call scan_fail(scanner, 'a block of entity dimension '//i2s(edim)//' (entity '//i2s(etag)// &
                       ') holds elements of type '//i2s(etype)//', which are those of '//trim(WHAT(dim)))
        return
      end if
      ent = entity_index(file_mesh, edim, etag)
      select case (etype)
      case (4, 5)
        call grow(file_mesh%cell_tag, file_mesh%cell_entity, file_mesh%ncell, nb, ntotal, err, file_mesh%cell_node)
      case (2, 3)
        call grow(file_mesh%face_tag, file_mesh%face_entity, file_mesh%nface, nb, ntotal, err, file_mesh%face_node)
      case (1)
        call grow(file_mesh%line_tag, file_mesh%line_entity, file_mesh%nline, nb, ntotal, err, file_mesh%line_node)
      case default
        call grow(file_mesh%point_node, file_mesh%point_entity, file_mesh%npoint, nb, ntotal, err)
      end select
      if (err%failed()) then
        call scan_fail(scanner, err%message, ERR_MEMORY)
        return
      end if
      do k = 1, nb
        tag = get_int(scanner, 'an element tag')
        if (scanner%err%failed()) return
        if (tag < 1) then
          call scan_fail(scanner, 'element tag '//i2s(tag)//' in $Elements: tags must be >= 1')
          return
        end if
        nodes = 0
        do j = 1, nv
          ntg = get_int(scanner, 'a node tag')
          if (scanner%err%failed()) return
          if (ntg < 1) then
            call scan_fail(scanner, 'element '//i2s(tag)//' refers to node tag '//i2s(ntg)//': tags must be >= 1')
            return
          end if
          nodes(j) = node_of(by_tag, ntg)
          if (nodes(j) == 0) then
            call scan_fail(scanner, 'element '//i2s(tag)//' refers to node '//i2s(ntg)//', which is not in $Nodes')
            return
          end if
        end do
        select case (etype)
        case (4, 5)
          file_mesh%ncell = file_mesh%ncell + 1
          file_mesh%cell_tag(file_mesh%ncell) = tag
          file_mesh%cell_entity(file_mesh%ncell) = ent
          file_mesh%cell_node(:, file_mesh%ncell) = nodes
        case (2, 3)
          file_mesh%nface = file_mesh%nface + 1
          file_mesh%face_tag(file_mesh%nface) = tag
          file_mesh%face_entity(file_mesh%nface) = ent
          file_mesh%face_node(:, file_mesh%nface) = nodes(1:4)
        case (1)
          file_mesh%nline = file_mesh%nline + 1
          file_mesh%line_tag(file_mesh%nline) = tag
          file_mesh%line_entity(file_mesh%nline) = ent
          file_mesh%line_node(:, file_mesh%nline) = nodes(1:2)
        case default
          file_mesh%npoint = file_mesh%npoint + 1
          file_mesh%point_entity(file_mesh%npoint) = ent
          file_mesh%point_node(file_mesh%npoint) = nodes(1)
        end select
      end do
    end do
    if (t /= ntotal) then
      call scan_fail(scanner, 'the element blocks hold '//i2s(t)//' elements, not the '//i2s(ntotal)//' announced')
      return
    end if
    call expect(scanner, '$EndElements')
  end subroutine read_elements_3d

  !> Room for `nb` more items after the `used` ones of one kind's arrays (a and e, and the
  !! columns of `nodes` if present): the capacity doubled, at least used + nb, at most
  !! `cap_max` (the elements announced). err (ERR_MEMORY, naming the cap_max elements): out
  !! of memory.
  subroutine grow(a, e, used, nb, cap_max, err, nodes)
    integer, allocatable, intent(inout) :: a(:), e(:)
    integer, intent(in) :: used, nb, cap_max
    type(error_t), intent(out) :: err
    integer, allocatable, intent(inout), optional :: nodes(:, :)
    integer, allocatable :: a2(:), e2(:), n2(:, :)
    integer :: cap, st
    if (used + nb <= size(a)) return
    cap = int(min(int(cap_max, i8), max(int(used, i8) + nb, 2_i8*size(a))))
    allocate (a2(cap), e2(cap), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for '//i2s(cap_max)//' elements')
      return
    end if
    a2(1:used) = a(1:used)
    e2(1:used) = e(1:used)
    call move_alloc(a2, a)
    call move_alloc(e2, e)
    if (present(nodes)) then
      allocate (n2(size(nodes, 1), cap), stat=st)
      if (st /= 0) then
        call err%set(ERR_MEMORY, 'not enough memory for '//i2s(cap_max)//' elements')
        return
      end if
      n2(:, 1:used) = nodes(:, 1:used)
      call move_alloc(n2, nodes)
    end if
  end subroutine grow

  !> The file node of tag `tag`, 0 if no node has it.
  integer function node_of(by_tag, tag) result(node)
    type(node_index_t), intent(in) :: by_tag
    integer, intent(in) :: tag
    integer :: slot
    node = 0
    if (by_tag%direct) then
      if (tag >= by_tag%lo .and. tag <= by_tag%hi) node = by_tag%node_of_tag(tag)
    else
      slot = hash_slot(by_tag%hash, int(tag, i8))
      if (by_tag%hash%key(slot) /= HASH_EMPTY) node = by_tag%node_of_slot(slot)
    end if
  end function node_of

  !> Move the index to a hash table sized for ntotal tags, holding the nnode tags read so far.
  !! err (ERR_MEMORY, naming the ntotal nodes): out of memory.
  subroutine index_to_hash(by_tag, node_tag, nnode, ntotal, err)
    type(node_index_t), intent(inout) :: by_tag
    integer, intent(in) :: node_tag(:)
    integer, intent(in) :: nnode, ntotal
    type(error_t), intent(out) :: err
    integer :: k, slot, st
    by_tag%direct = .false.
    if (allocated(by_tag%node_of_tag)) deallocate (by_tag%node_of_tag)
    st = 0
    call hash_init(by_tag%hash, ntotal, err)
    if (.not. err%failed()) allocate (by_tag%node_of_slot(0:by_tag%hash%mask), stat=st)
    if (err%failed() .or. st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for '//i2s(ntotal)//' nodes')
      return
    end if
    do k = 1, nnode
      slot = hash_slot(by_tag%hash, int(node_tag(k), i8))
      by_tag%hash%key(slot) = node_tag(k)
      by_tag%node_of_slot(slot) = k
    end do
  end subroutine index_to_hash

  !> The sentence refusing an element type.
  function unsupported_type(etype) result(s)
    integer, intent(in) :: etype
    character(len=:), allocatable :: s
    select case (etype)
    case (4, 5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29:35, 92, 93)
      s = 'has 3D elements (type '//i2s(etype)//'), and a 2D deck reads only 2D meshes (a 3D deck: &scene '// &
          'dimension=3)'
    case (8, 26, 27, 28)
      s = 'has higher-order lines (type '//i2s(etype)//'); use first-order elements '// &
          '(gmsh -order 1, Mesh.ElementOrder = 1)'
    case (9, 20, 21, 22, 23, 24, 25)
      s = 'has higher-order triangles (type '//i2s(etype)//', e.g. 9 = 6-node second order); '// &
          'use first-order elements (gmsh -order 1, Mesh.ElementOrder = 1)'
    case (10, 16, 36, 37, 38)
      s = 'has higher-order quadrangles (type '//i2s(etype)//', e.g. 10 = 9-node second order); '// &
          'use first-order elements (gmsh -order 1, Mesh.ElementOrder = 1)'
    case default
      s = 'has elements of type '//i2s(etype)//'; only first-order lines (1), triangles (2), '// &
          'quadrangles (3) and points (15) are read'
    end select
  end function unsupported_type

  !> The sentence refusing an element type in a 3D run.
  function unsupported_type_3d(etype) result(s)
    integer, intent(in) :: etype
    character(len=:), allocatable :: s
    character(len=*), parameter :: FIRST = '; use first-order elements (gmsh -order 1, Mesh.ElementOrder = 1)'
    select case (etype)
    case (11, 29, 30, 31, 32, 33)
      s = 'has higher-order tetrahedra (type '//i2s(etype)//', e.g. 11 = 10-node second order)'//FIRST
    case (12, 17, 92, 93)
      s = 'has higher-order hexahedra (type '//i2s(etype)//', e.g. 12 = 27-node and 17 = 20-node second '// &
          'order)'//FIRST
    case (6, 13, 18)
      s = 'has prisms (type '//i2s(etype)//'), and only tetrahedra (type 4) and hexahedra (type 5) are read; '// &
          'mesh the volumes with tetrahedra only or hexahedra only'
    case (7, 14, 19)
      s = 'has pyramids (type '//i2s(etype)//'), and only tetrahedra (type 4) and hexahedra (type 5) are '// &
          'read; mesh the volumes with tetrahedra only or hexahedra only'
    case (8, 26, 27, 28, 9, 20, 21, 22, 23, 24, 25, 10, 16, 36, 37, 38)
      s = unsupported_type(etype)
    case default
      s = 'has elements of type '//i2s(etype)//'; only first-order points (15), lines (1), triangles (2), '// &
          'quadrangles (3), tetrahedra (4) and hexahedra (5) are read'
    end select
  end function unsupported_type_3d

  !> A real for messages.
  function real_text(x) result(s)
    real(wp), intent(in) :: x
    character(len=24) :: s
    write (s, '(es12.5)') x
    s = adjustl(s)
  end function real_text

end module gmsh_msh
