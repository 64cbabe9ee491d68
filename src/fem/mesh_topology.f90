!> One body's mesh from what a mesh file holds (physical groups, entities, nodes, cells,
!! lines and points, in file order; module gmsh_msh reads them): the cells of the body's
!! physical surface, its nodes renumbered 1..nnode in increasing tag order, its cells
!! counter-clockwise (degenerate cells and non-convex quadrangles refused), and its groups.
!! A group keeps the line elements of its physical curve that are boundary edges of the body
!! (edges of exactly one body cell), oriented as that cell traverses them; the nodes of its
!! lines inside the body (edges of two body cells) are kept as single nodes. A physical point
!! is a group of single nodes: those of its points that are nodes of the body. A point's
!! node in no cell of the file (a free geometry point) is the body's node at the same place,
!! within 1e-9 times the body's size, if it has one.
module mesh_topology
  use kinds, only: wp, i8
  use config, only: ELEM_Q1, ELEM_P1, ELEM_MIXED
  use strings, only: i2s
  use int_hash, only: int_hash_t, hash_init, hash_slot, HASH_EMPTY
  use mesh, only: mesh_t
  implicit none (type, external)
  private

  public :: body_from_file, add_physical, entity_index

  integer, parameter :: BAD_INPUT = 1, OTHER_FAILURE = 3
  real(wp), parameter :: AREA_TOL = 1.0e-12_wp       ! degenerate: |area| < AREA_TOL * (longest edge)^2

  !> A text of its own length (an array of names).
  type, public :: name_t
    character(len=:), allocatable :: s
  end type name_t

  !> A point, curve or surface entity and its physical tags.
  type, public :: entity_t
    integer :: dim = 0, tag = 0
    integer, allocatable :: phys(:)
  end type entity_t

  !> What a mesh file holds, before a body is chosen. Nodes, cells, lines and points are
  !! numbered in file order; elements refer to nodes by that number, to entities by their
  !! index in `ent` (0: the file has no entity for them).
  type, public :: file_mesh_t
    integer :: nphys = 0                       !< physical groups (named or not)
    integer, allocatable :: phys_dim(:), phys_tag(:)
    type(name_t), allocatable :: phys_name(:)
    integer :: nent = 0                        !< point, curve and surface entities
    type(entity_t), allocatable :: ent(:)
    integer :: nnode = 0                       !< nodes
    integer, allocatable :: node_tag(:)
    real(wp), allocatable :: node_xy(:, :)
    integer :: ncell = 0                       !< triangles and quadrangles
    integer, allocatable :: cell_tag(:), cell_entity(:)
    integer, allocatable :: cell_node(:, :)    !< (4, ncell) nodes; a triangle's 4th is 0
    integer :: nline = 0                       !< 2-node lines
    integer, allocatable :: line_entity(:), line_node(:, :)
    integer :: npoint = 0                      !< point elements
    integer, allocatable :: point_entity(:), point_node(:)
  end type file_mesh_t

contains

  !> Add a physical group (dim, tag) named `name` unless it is there already.
  subroutine add_physical(d, dim, tag, name)
    type(file_mesh_t), intent(inout) :: d
    integer, intent(in) :: dim, tag
    character(len=*), intent(in) :: name
    integer, allocatable :: idim(:), itag(:)
    type(name_t), allocatable :: nm(:)
    integer :: k
    if (.not. allocated(d%phys_dim)) allocate (d%phys_dim(8), d%phys_tag(8), d%phys_name(8))
    do k = 1, d%nphys
      if (d%phys_dim(k) == dim .and. d%phys_tag(k) == tag) return
    end do
    if (d%nphys == size(d%phys_dim)) then
      allocate (idim(2*d%nphys), itag(2*d%nphys), nm(2*d%nphys))
      idim(1:d%nphys) = d%phys_dim
      itag(1:d%nphys) = d%phys_tag
      do k = 1, d%nphys
        call move_alloc(d%phys_name(k)%s, nm(k)%s)
      end do
      call move_alloc(idim, d%phys_dim)
      call move_alloc(itag, d%phys_tag)
      call move_alloc(nm, d%phys_name)
    end if
    d%nphys = d%nphys + 1
    d%phys_dim(d%nphys) = dim
    d%phys_tag(d%nphys) = tag
    d%phys_name(d%nphys)%s = name
  end subroutine add_physical

  !> The index in d%ent of entity (dim, tag), 0 if it has none.
  integer function entity_index(d, dim, tag) result(k)
    type(file_mesh_t), intent(in) :: d
    integer, intent(in) :: dim, tag
    do k = 1, d%nent
      if (d%ent(k)%dim == dim .and. d%ent(k)%tag == tag) return
    end do
    k = 0
  end function entity_index

  !> Record a failure (the first one only).
  subroutine refuse(info, err, text, code)
    integer, intent(inout) :: info
    character(len=:), allocatable, intent(inout) :: err
    character(len=*), intent(in) :: text
    integer, intent(in), optional :: code
    if (info /= 0) return
    info = BAD_INPUT
    if (present(code)) info = code
    err = text
  end subroutine refuse

  !> One body from what a mesh file holds: choose the body's cells (those of the physical
  !! surface `region`), renumber its nodes, orient and check its cells, find its groups.
  !! On failure info = 1 (bad input) or 3 (memory) and err is a phrase about the file
  !! (its subject the file: 'has no physical surface ...').
  subroutine body_from_file(d, region, path, mesh, info, err)
    type(file_mesh_t), intent(in) :: d                  !< the file's groups, entities, nodes, elements
    character(len=*), intent(in) :: region              !< physical surface name of the body, or ''
    character(len=*), intent(in) :: path                !< the file, kept as mesh%source
    type(mesh_t), intent(inout) :: mesh                 !< the body's mesh
    integer, intent(out) :: info                        !< 0; 1 bad input; 3 other failure
    character(len=:), allocatable, intent(out) :: err   !< the failure, when info /= 0
    integer :: target, k, c, nsurf, nc, st, nq
    logical, allocatable :: in_ent(:)
    integer, allocatable :: sel(:), body_node(:), order(:)
    character(len=:), allocatable :: surfaces

    info = 0
    ! the physical surface of the body
    surfaces = ''
    nsurf = 0
    target = 0
    do k = 1, d%nphys
      if (d%phys_dim(k) /= 2) cycle
      nsurf = nsurf + 1
      surfaces = surfaces//merge(', ', '  ', nsurf > 1)//"'"//d%phys_name(k)%s//"'"
      if (len(region) > 0 .and. d%phys_name(k)%s == region) target = k
    end do
    surfaces = trim(adjustl(surfaces))
    if (len(region) > 0 .and. target == 0) then
      if (nsurf == 0) then
        call refuse(info, err, "has no physical surface '"//region//"' (it has no physical surfaces)")
      else
        call refuse(info, err, "has no physical surface '"//region//"' (its physical surfaces: "//surfaces//')')
      end if
      return
    end if
    if (len(region) == 0 .and. nsurf > 1) then
      call refuse(info, err, 'holds '//i2s(nsurf)//' physical surfaces ('//surfaces// &
                '); name the body''s one as its region')
      return
    end if
    if (len(region) == 0 .and. nsurf == 1) then
      do k = 1, d%nphys
        if (d%phys_dim(k) == 2) target = k
      end do
    end if

    ! its cells: those of the surface entities in the group (every one without a group)
    allocate (in_ent(0:d%nent))
    in_ent = target == 0
    do k = 1, d%nent
      if (target > 0) in_ent(k) = d%ent(k)%dim == 2 .and. any(d%ent(k)%phys == d%phys_tag(target))
    end do
    sel = pack([(c, c=1, d%ncell)], in_ent(d%cell_entity(1:d%ncell)))
    nc = size(sel)
    if (nc == 0) then
      if (target > 0) then
        call refuse(info, err, "physical surface '"//d%phys_name(target)%s//"' has no triangles or quadrangles")
      else
        call refuse(info, err, 'has no triangles or quadrangles')
      end if
      return
    end if

    ! its nodes, in increasing tag order
    allocate (body_node(d%nnode), stat=st)
    if (st /= 0) then
      call refuse(info, err, 'not enough memory', OTHER_FAILURE)
      return
    end if
    body_node = 0
    do k = 1, nc
      do c = 1, 4
        if (d%cell_node(c, sel(k)) > 0) body_node(d%cell_node(c, sel(k))) = 1
      end do
    end do
    order = pack([(k, k=1, d%nnode)], body_node > 0)
    call sort_by_tag(order, d%node_tag)
    mesh%nnode = size(order)
    allocate (mesh%xy(2, mesh%nnode), mesh%node_tag(mesh%nnode))
    do k = 1, mesh%nnode
      body_node(order(k)) = k
      mesh%xy(:, k) = d%node_xy(:, order(k))
      mesh%node_tag(k) = d%node_tag(order(k))
    end do

    ! its cells
    nq = count(d%cell_node(4, sel) > 0)
    mesh%ncell = nc
    mesh%nvert = merge(4, 3, nq > 0)
    if (nq == nc) then
      mesh%element = ELEM_Q1
    else if (nq == 0) then
      mesh%element = ELEM_P1
    else
      mesh%element = ELEM_MIXED
    end if
    allocate (mesh%cells(mesh%nvert, nc), mesh%cell_type(nc), mesh%cell_tag(nc))
    mesh%cells = 0
    do k = 1, nc
      c = sel(k)
      mesh%cell_tag(k) = d%cell_tag(c)
      if (d%cell_node(4, c) > 0) then
        mesh%cell_type(k) = ELEM_Q1
        mesh%cells(1:4, k) = body_node(d%cell_node(1:4, c))
      else
        mesh%cell_type(k) = ELEM_P1
        mesh%cells(1:3, k) = body_node(d%cell_node(1:3, c))
      end if
      call orient_cell(mesh, k, info, err)
      if (info /= 0) return
    end do

    mesh%structured = .false.
    mesh%source = path
    mesh%nx = 0
    mesh%ny = 0
    mesh%x0 = minval(mesh%xy(1, :))
    mesh%y0 = minval(mesh%xy(2, :))
    mesh%width = maxval(mesh%xy(1, :)) - mesh%x0
    mesh%height = maxval(mesh%xy(2, :)) - mesh%y0

    call boundary_groups(d, body_node, mesh, info, err)
    if (info == 0) call point_groups(d, body_node, mesh)
  end subroutine body_from_file

  !> Put cell k counter-clockwise; refuse it if degenerate or (a quadrangle) not convex.
  subroutine orient_cell(mesh, k, info, err)
    type(mesh_t), intent(inout) :: mesh
    integer, intent(in) :: k
    integer, intent(inout) :: info
    character(len=:), allocatable, intent(inout) :: err
    real(wp) :: p(2, 4), area2, h2, turn
    integer :: nv, i, i1, i2
    character(len=*), parameter :: what(2) = ['quadrangle', 'triangle  ']

    nv = merge(4, 3, mesh%cell_type(k) == ELEM_Q1)
    p(:, 1:nv) = mesh%xy(:, mesh%cells(1:nv, k))
    area2 = 0.0_wp
    h2 = 0.0_wp
    do i = 1, nv
      i1 = modulo(i, nv) + 1
      area2 = area2 + p(1, i)*p(2, i1) - p(1, i1)*p(2, i)
      h2 = max(h2, sum((p(:, i1) - p(:, i))**2))
    end do
    if (.not. abs(area2) > 2.0_wp*AREA_TOL*h2) then
      call refuse(info, err, 'element '//i2s(mesh%cell_tag(k))//' (a '//trim(what(mesh%cell_type(k)))// &
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
          call refuse(info, err, 'element '//i2s(mesh%cell_tag(k))//' is not a convex quadrangle '// &
                    '(inverted, self-crossing or with a re-entrant or straight corner at node '// &
                    i2s(mesh%node_tag(mesh%cells(i1, k)))//')')
          return
        end if
      end do
    end if
  end subroutine orient_cell

  !> One edge group per physical curve: its lines that are boundary edges of the body, and
  !! the nodes of its lines inside the body as single nodes (a curve inside the body gives
  !! a group of nodes only). The lines' edges are hashed (a small table), then every cell
  !! edge is looked up in it: a line edge met in exactly one cell is a boundary edge,
  !! oriented as that cell has it; one met in two is inside the body.
  subroutine boundary_groups(d, body_node, mesh, info, err)
    type(file_mesh_t), intent(in) :: d
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(mesh_t), intent(inout) :: mesh
    integer, intent(inout) :: info
    character(len=:), allocatable, intent(inout) :: err
    type(int_hash_t) :: h
    integer, allocatable :: line_slot(:), ecount(:), ecell(:), elocal(:), edges(:, :), cells(:), inner(:)
    logical, allocatable :: on(:)
    integer :: c, i, nv, a, b, slot, st, p, l, ne, ng, ni
    integer(i8) :: key, nn1

    ! the body's line edges, keyed by their two nodes (line_slot = 0: not a body edge)
    call hash_init(h, d%nline, st)
    if (st == 0) allocate (line_slot(d%nline), ecount(0:h%mask), ecell(0:h%mask), elocal(0:h%mask), &
                           edges(2, d%nline), cells(d%nline), inner(2*d%nline), on(mesh%nnode), stat=st)
    if (st /= 0) then
      call refuse(info, err, 'not enough memory for the boundary edges', OTHER_FAILURE)
      return
    end if
    line_slot = -1
    ecount = 0
    on = .false.
    nn1 = mesh%nnode + 1
    do l = 1, d%nline
      if (d%line_entity(l) == 0) cycle
      a = body_node(d%line_node(1, l))
      b = body_node(d%line_node(2, l))
      if (a == 0 .or. b == 0 .or. a == b) cycle
      key = min(a, b)*nn1 + max(a, b)
      slot = hash_slot(h, key)
      h%key(slot) = key
      line_slot(l) = slot
    end do

    ! how many cells have each of them, and the last one
    do c = 1, mesh%ncell
      nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
      do i = 1, nv
        a = mesh%cells(i, c)
        b = mesh%cells(modulo(i, nv) + 1, c)
        key = min(a, b)*nn1 + max(a, b)
        slot = hash_slot(h, key)
        if (h%key(slot) /= key) cycle
        ecount(slot) = ecount(slot) + 1
        ecell(slot) = c
        elocal(slot) = i
      end do
    end do

    mesh%file_groups = ''
    allocate (mesh%group(count(d%phys_dim(1:d%nphys) == 1 .or. d%phys_dim(1:d%nphys) == 0)))  ! room for points
    ng = 0
    do p = 1, d%nphys
      if (d%phys_dim(p) /= 1) cycle
      mesh%file_groups = trim(mesh%file_groups//' '//d%phys_name(p)%s)
      ne = 0
      ni = 0
      do l = 1, d%nline
        if (line_slot(l) < 0) cycle
        if (.not. any(d%ent(d%line_entity(l))%phys == d%phys_tag(p))) cycle
        slot = line_slot(l)
        if (ecount(slot) == 0) cycle          ! not an edge of the body's cells
        if (ecount(slot) > 1) then            ! inside the body: its nodes, once each
          do i = 1, 2
            a = body_node(d%line_node(i, l))
            if (on(a)) cycle
            on(a) = .true.
            ni = ni + 1
            inner(ni) = a
          end do
          cycle
        end if
        c = ecell(slot)
        nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
        ne = ne + 1
        edges(:, ne) = [mesh%cells(elocal(slot), c), mesh%cells(modulo(elocal(slot), nv) + 1, c)]
        cells(ne) = c
      end do
      on(inner(1:ni)) = .false.
      if (ne == 0 .and. ni == 0) cycle
      ng = ng + 1
      mesh%group(ng)%name = d%phys_name(p)%s
      mesh%group(ng)%nedge = ne
      mesh%group(ng)%edge = edges(:, 1:ne)
      mesh%group(ng)%cell = cells(1:ne)
      mesh%group(ng)%nnode = ni
      mesh%group(ng)%node = inner(1:ni)
    end do
    mesh%file_groups = trim(adjustl(mesh%file_groups))
    mesh%ngroup = ng
  end subroutine boundary_groups

  !> One node group per physical point with nodes in the body, after the edge groups (a
  !! physical point named as a physical curve adds its nodes to the curve's group); the
  !! points' names go to file_groups. A point's node is the body's if the body's cells have
  !! it; a node in no cell of the file is matched to the body's node at its place.
  subroutine point_groups(d, body_node, mesh)
    type(file_mesh_t), intent(in) :: d
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(mesh_t), intent(inout) :: mesh
    logical, allocatable :: in_cell(:)
    integer, allocatable :: nodes(:)
    integer :: p, l, n, nn, g, c, i
    real(wp) :: tol
    character(len=:), allocatable :: names

    names = ''
    allocate (nodes(d%npoint))
    tol = 1.0e-9_wp*max(mesh%width, mesh%height)
    do p = 1, d%nphys
      if (d%phys_dim(p) /= 0) cycle
      names = names//' '//d%phys_name(p)%s
      nn = 0
      do l = 1, d%npoint
        if (d%point_entity(l) == 0) cycle
        if (.not. any(d%ent(d%point_entity(l))%phys == d%phys_tag(p))) cycle
        n = body_node(d%point_node(l))
        if (n == 0) then
          if (.not. allocated(in_cell)) then
            allocate (in_cell(d%nnode))
            in_cell = .false.
            do c = 1, d%ncell
              do i = 1, 4
                if (d%cell_node(i, c) > 0) in_cell(d%cell_node(i, c)) = .true.
              end do
            end do
          end if
          if (.not. in_cell(d%point_node(l))) n = node_at(mesh, d%node_xy(:, d%point_node(l)), tol)
        end if
        if (n == 0) cycle
        if (any(nodes(1:nn) == n)) cycle
        nn = nn + 1
        nodes(nn) = n
      end do
      if (nn == 0) cycle
      g = 0
      do c = 1, mesh%ngroup
        if (mesh%group(c)%name == d%phys_name(p)%s) g = c
      end do
      if (g == 0) then
        mesh%ngroup = mesh%ngroup + 1
        g = mesh%ngroup
        mesh%group(g)%name = d%phys_name(p)%s
        mesh%group(g)%point = .true.
        allocate (mesh%group(g)%edge(2, 0), mesh%group(g)%cell(0))
      end if
      if (.not. allocated(mesh%group(g)%node)) allocate (mesh%group(g)%node(0))
      mesh%group(g)%node = [mesh%group(g)%node, nodes(1:nn)]
      mesh%group(g)%nnode = size(mesh%group(g)%node)
    end do
    if (len(names) == 0) return
    if (len(mesh%file_groups) == 0) mesh%file_groups = '(none)'
    mesh%file_groups = mesh%file_groups//'; physical points:'//names
  end subroutine point_groups

  !> The body node within tol of xy (the nearest), 0 if none.
  integer function node_at(mesh, xy, tol) result(n)
    type(mesh_t), intent(in) :: mesh
    real(wp), intent(in) :: xy(2), tol
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

  !> Sort the file node indices `idx` by increasing tag (bottom-up merge sort).
  subroutine sort_by_tag(idx, tag)
    integer, intent(inout) :: idx(:)
    integer, intent(in) :: tag(:)
    integer, allocatable :: work(:)
    integer :: n, width, lo, mid, hi, i, j, k
    n = size(idx)
    if (n < 2) return
    if (all(tag(idx(2:n)) > tag(idx(1:n - 1)))) return     ! the usual case: already sorted
    allocate (work(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width, n + 1)
        hi = min(lo + 2*width, n + 1)
        i = lo
        j = mid
        do k = lo, hi - 1
          if (i < mid .and. (j >= hi .or. tag(idx(min(i, n))) <= tag(idx(min(j, n))))) then
            work(k) = idx(i)
            i = i + 1
          else
            work(k) = idx(j)
            j = j + 1
          end if
        end do
      end do
      idx = work
      width = 2*width
    end do
  end subroutine sort_by_tag

end module mesh_topology
