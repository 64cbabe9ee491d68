!> One body's volume mesh (a 3D run) from what a mesh file holds (module mesh_topology's
!! file_mesh_t, filled by module gmsh_msh): the tetrahedra and hexahedra of the body's
!! physical volume, each positively oriented (a cell of negative Jacobian turned; a
!! degenerate tetrahedron, and a hexahedron whose Jacobian at its corners and centre is not
!! of one sign, refused), checked (no cell listed twice, no two cells on one side of a face,
!! no face of three cells, one connected piece), then numbered for locality
!! (mesh_topology's number_for_locality; mesh%file_node and mesh%file_cell keep the file's
!! order). The mesh_t holds xy(3, nnode), cells(nvert, ncell) in Gmsh's vertex order
!! (nvert = 8 with any hexahedron, a tetrahedron's 5th to 8th vertices then 0), cell_type
!! ELEM_TET4 or ELEM_HEX8, element ELEM_TET4, ELEM_HEX8 or ELEM_MIXED.
!!
!! The faces of the body's cells are hashed by their sorted nodes (an open-addressing table,
!! one slot per face, the first cell met with it and how many cells have it), so the checks
!! and the groups cost linear time. A group keeps the triangles and quadrangles of its
!! physical surface that are boundary faces of the body (faces of exactly one cell),
!! oriented as that cell has them: counter-clockwise seen from outside, the right-hand rule
!! giving the outward normal (group(g)%edge(nvf, nedge), nvf 3, or 4 when the group has a
!! quadrangle, a triangle's 4th node then 0; group(g)%cell the cell). The nodes of its faces
!! inside the body (faces of two cells) are kept as single nodes; a face whose nodes are all
!! the body's but which is no face of its cells is bad input. A physical curve is a group of
!! nodes (those of its lines with both nodes in the body), a physical point as in 2D
!! (mesh_topology's point_groups); a curve or point named as a surface adds its nodes to the
!! surface's group. The other physical volumes holding cells of the body are its regions.
module volume_topology
  use kinds, only: wp, i8
  use config, only: ELEM_HEX8, ELEM_TET4, ELEM_MIXED
  use errors, only: error_t, ERR_INPUT, ERR_MEMORY
  use strings, only: i2s, sci, text_buffer_t
  use int_hash, only: int_hash_t, hash_init, hash_slot
  use sorting, only: merge_sort_by_keys, sort_ints
  use mesh, only: mesh_t
  use mesh_topology, only: file_mesh_t, body_group, group_members, entity_cells, cell_regions, point_groups, number_for_locality, &
                           check_one_piece, body_file_nodes
  implicit none (type, external)
  private

  public :: body_from_volumes

  ! degenerate: 6 |volume| of a tetrahedron, or 8 |Jacobian| at a hexahedron's corner, below
  ! VOL_TOL * (longest edge)^3
  real(wp), parameter :: VOL_TOL = 1.0e-12_wp
  ! the largest coordinate whose cell volumes and cubed edges stay finite (64 x^3 <= huge)
  real(wp), parameter :: COORD_MAX = 0.25_wp*huge(1.0_wp)**(1.0_wp/3.0_wp)
  !> the faces of a positively oriented cell, each counter-clockwise seen from outside
  !! (Gmsh's vertex order: a tetrahedron is positive when (x2 - x1, x3 - x1, x4 - x1) is
  !! right-handed; a hexahedron's reference vertices (-1,-1,-1), (1,-1,-1), (1,1,-1),
  !! (-1,1,-1), then the same at zeta = 1)
  integer, parameter :: TET_FACE(3, 4) = reshape([1, 3, 2, 1, 2, 4, 1, 4, 3, 2, 3, 4], [3, 4])
  integer, parameter :: HEX_FACE(4, 6) = reshape([1, 4, 3, 2, 5, 6, 7, 8, 1, 2, 6, 5, 3, 4, 8, 7, &
                                                  1, 5, 8, 4, 2, 3, 7, 6], [4, 6])
  ! a hexahedron's reference vertices
  real(wp), parameter :: XA(8) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: EA(8) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: ZA(8) = [-1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp]
  ! a hexahedron's 12 edges, a tetrahedron's 6
  integer, parameter :: HEX_EDGE(2, 12) = reshape([1, 2, 2, 3, 3, 4, 4, 1, 5, 6, 6, 7, 7, 8, 8, 5, 1, 5, 2, 6, &
                                                   3, 7, 4, 8], [2, 12])
  integer, parameter :: TET_EDGE(2, 6) = reshape([1, 2, 1, 3, 1, 4, 2, 3, 2, 4, 3, 4], [2, 6])

  !> The faces of the body's cells keyed by their sorted nodes, one 64-bit word per slot
  !! (one memory access per probe): 0 (empty), or bits 0..30 the face, 8 (c - 1) + f (local
  !! face f of cell c, the first cell met with it), bits 31..32 how many cells have it (1 or
  !! 2), bits 33..62 the key's hash without its 2 low bits (so that a key is compared in full
  !! only where its hash matches).
  type :: face_table_t
    integer(i8) :: mask = -1
    integer(i8), allocatable :: v(:)
  end type face_table_t

  integer(i8), parameter :: FACE_BITS = 2_i8**31 - 1

contains

  !> One body from what a mesh file holds, in a 3D run: choose the body's cells (those of
  !! the physical volume `region`; '' the file's only one, or every volume element of a file
  !! without physical volumes), number its nodes by tag, orient and check its cells, find its
  !! regions and groups, then number its nodes and cells for locality. On failure err holds
  !! ERR_INPUT (bad input) or ERR_MEMORY and a phrase about the file (its subject the file).
  subroutine body_from_volumes(file_mesh, region, path, mesh, err)
    type(file_mesh_t), intent(in), target :: file_mesh  !< the file's groups, entities, nodes, elements
    character(len=*), intent(in) :: region              !< physical volume name of the body, or ''
    character(len=*), intent(in) :: path                !< the file, kept as mesh%source
    type(mesh_t), intent(inout) :: mesh                 !< the body's mesh
    type(error_t), intent(out) :: err                   !< the failure, if any
    integer :: volume, k, c, ncell, st, nhex
    logical, allocatable :: in_entity(:)
    integer, allocatable :: file_cell(:), body_node(:), order(:)
    type(face_table_t) :: faces

    ! the physical volume of the body
    call body_group(file_mesh, region, 3, surface_hint(), volume, err)
    if (err%failed()) return

    ! its cells: those of the volume entities in the group (every one without a group)
    allocate (in_entity(0:file_mesh%nent))
    in_entity = volume == 0
    do k = 1, file_mesh%nent
      if (volume > 0) in_entity(k) = file_mesh%ent(k)%dim == 3 .and. &
                                     any(file_mesh%ent(k)%phys == file_mesh%phys_tag(volume))
    end do
    file_cell = entity_cells(file_mesh, in_entity)
    ncell = size(file_cell)
    if (ncell == 0) then
      if (volume > 0) then
        if (file_mesh%nent == 0) then
          call err%set(ERR_INPUT, "names physical volume '"//file_mesh%phys_name(volume)%s// &
                       "' but has no $Entities section, which ties elements to physical groups")
        else
          call err%set(ERR_INPUT, "physical volume '"//file_mesh%phys_name(volume)%s// &
                       "' has no tetrahedra or hexahedra")
        end if
      else if (file_mesh%nface > 0) then
        call err%set(ERR_INPUT, 'has no tetrahedra or hexahedra, only triangles and quadrangles: a 2D mesh, in '// &
                     'a 3D deck, whose bodies are volumes (mesh them with gmsh -3); a 2D deck reads 2D meshes')
      else
        call err%set(ERR_INPUT, 'has no tetrahedra or hexahedra')
      end if
      return
    end if

    ! its nodes, in increasing tag order
    call body_file_nodes(file_mesh, file_cell, 8, body_node, order, err)
    if (err%failed()) return
    mesh%nnode = size(order)
    allocate (mesh%xy(3, mesh%nnode), mesh%node_tag(mesh%nnode), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for '//i2s(mesh%nnode)//' nodes')
      return
    end if
    do k = 1, mesh%nnode
      body_node(order(k)) = k
      mesh%xy(:, k) = file_mesh%node_xy(:, order(k))
      mesh%node_tag(k) = file_mesh%node_tag(order(k))
    end do
    do k = 1, mesh%nnode
      if (maxval(abs(mesh%xy(:, k))) > COORD_MAX) then
        call err%set(ERR_INPUT, 'node '//i2s(mesh%node_tag(k))//' has a coordinate of magnitude '// &
                     sci(maxval(abs(mesh%xy(:, k))))//': beyond '//sci(COORD_MAX)// &
                     ' the cells'' volumes overflow double precision; scale the mesh')
        return
      end if
    end do

    ! its cells, positively oriented
    nhex = count(file_mesh%cell_node(5, file_cell) > 0)
    mesh%ncell = ncell
    mesh%nvert = merge(8, 4, nhex > 0)
    if (nhex == ncell) then
      mesh%element = ELEM_HEX8
    else if (nhex == 0) then
      mesh%element = ELEM_TET4
    else
      mesh%element = ELEM_MIXED
    end if
    allocate (mesh%cells(mesh%nvert, ncell), mesh%cell_type(ncell), mesh%cell_tag(ncell), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for '//i2s(ncell)//' cells')
      return
    end if
    mesh%cells = 0
    do k = 1, ncell
      c = file_cell(k)
      mesh%cell_tag(k) = file_mesh%cell_tag(c)
      if (file_mesh%cell_node(5, c) > 0) then
        mesh%cell_type(k) = ELEM_HEX8
        mesh%cells(1:8, k) = body_node(file_mesh%cell_node(1:8, c))
      else
        mesh%cell_type(k) = ELEM_TET4
        mesh%cells(1:4, k) = body_node(file_mesh%cell_node(1:4, c))
      end if
      call orient_cell(mesh, k, err)
      if (err%failed()) return
    end do
    call check_duplicate_cells(mesh, err)
    if (err%failed()) return
    call hash_faces(mesh, faces, err)
    if (err%failed()) return
    call check_one_piece(mesh, err)
    if (err%failed()) return

    mesh%structured = .false.
    mesh%box = .false.
    mesh%source = path
    mesh%nx = 0
    mesh%ny = 0
    mesh%nz = 0
    mesh%x0 = minval(mesh%xy(1, :))
    mesh%y0 = minval(mesh%xy(2, :))
    mesh%z0 = minval(mesh%xy(3, :))
    mesh%width = maxval(mesh%xy(1, :)) - mesh%x0
    mesh%height = maxval(mesh%xy(2, :)) - mesh%y0
    mesh%depth = maxval(mesh%xy(3, :)) - mesh%z0

    call cell_regions(file_mesh, 3, volume, file_cell, mesh)
    call face_groups(file_mesh, body_node, faces, mesh, err)
    if (allocated(faces%v)) deallocate (faces%v)
    if (.not. err%failed()) call curve_groups(file_mesh, body_node, mesh, err)
    if (.not. err%failed()) call point_groups(file_mesh, body_node, mesh, err)
    if (.not. err%failed()) call number_for_locality(mesh, err)

  contains

    !> When `region` names a physical surface: that a body of a 3D deck is a volume.
    function surface_hint() result(s)
      character(len=:), allocatable :: s
      integer :: j
      s = ''
      do j = 1, file_mesh%nphys
        if (file_mesh%phys_dim(j) == 2 .and. file_mesh%phys_name(j)%s == region) then
          s = "; '"//region//"' is a physical surface, and a body of a 3D deck is a physical volume"
          return
        end if
      end do
    end function surface_hint
  end subroutine body_from_volumes

  ! ---- cells --------------------------------------------------------------------------------

  !> Orient cell k positively: a tetrahedron of negative volume gets its vertices 2 and 3
  !! swapped; a hexahedron whose Jacobian is negative at its 8 corners and its centre gets
  !! its vertices 2 and 4, 6 and 8 swapped (its reference axes xi and eta exchanged). The first
  !! vertex is kept. A degenerate tetrahedron, and a hexahedron whose Jacobian there is not
  !! of one sign (inverted at a corner, twisted, or flat), are refused naming the element.
  subroutine orient_cell(mesh, k, err)
    type(mesh_t), intent(inout) :: mesh
    integer, intent(in) :: k
    type(error_t), intent(inout) :: err
    real(wp) :: p(3, 8), h2, det, dets(9), tol
    integer :: i, bad

    if (mesh%cell_type(k) == ELEM_TET4) then
      do i = 1, 4
        p(:, i) = mesh%xy(:, mesh%cells(i, k))
      end do
      h2 = 0.0_wp
      do i = 1, 6
        h2 = max(h2, sum((p(:, TET_EDGE(2, i)) - p(:, TET_EDGE(1, i)))**2))
      end do
      det = triple(p(:, 2) - p(:, 1), p(:, 3) - p(:, 1), p(:, 4) - p(:, 1))
      if (.not. abs(det) > VOL_TOL*h2*sqrt(h2)) then
        call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' (a tetrahedron) is degenerate: its '// &
                     'volume is zero or nearly so')
        return
      end if
      if (det < 0.0_wp) mesh%cells(1:4, k) = mesh%cells([1, 3, 2, 4], k)
      return
    end if
    do i = 1, 8
      p(:, i) = mesh%xy(:, mesh%cells(i, k))
    end do
    h2 = 0.0_wp
    do i = 1, 12
      h2 = max(h2, sum((p(:, HEX_EDGE(2, i)) - p(:, HEX_EDGE(1, i)))**2))
    end do
    do i = 1, 8
      dets(i) = hex_jacobian(p, XA(i), EA(i), ZA(i))
    end do
    dets(9) = hex_jacobian(p, 0.0_wp, 0.0_wp, 0.0_wp)
    tol = VOL_TOL*h2*sqrt(h2)/8.0_wp
    if (all(dets > tol)) return
    if (all(dets < -tol)) then
      mesh%cells(1:8, k) = mesh%cells([1, 4, 3, 2, 5, 8, 7, 6], k)
      return
    end if
    if (all(abs(dets) <= tol)) then
      call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' (a hexahedron) is degenerate: its '// &
                   'volume is zero or nearly so')
      return
    end if
    ! the corner (or the centre) against the sign of the largest Jacobian
    if (maxval(dets) >= -minval(dets)) then
      bad = minloc(dets, dim=1)
    else
      bad = maxloc(dets, dim=1)
    end if
    if (bad <= 8) then
      call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' (a hexahedron) is inverted, twisted or '// &
                   'flat at its corner node '//i2s(mesh%node_tag(mesh%cells(bad, k)))//': its Jacobian is not '// &
                   'of one sign over its 8 corners (a wrong node order or a node misplaced)')
    else
      call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(k))//' (a hexahedron) is inverted or twisted: its '// &
                   'Jacobian at its centre is not of the sign of those at its corners')
    end if
  end subroutine orient_cell

  !> The Jacobian determinant of the trilinear map of a hexahedron's vertices p at the
  !! reference point (xi, eta, zeta).
  pure real(wp) function hex_jacobian(p, xi, eta, zeta) result(det)
    real(wp), intent(in) :: p(3, 8), xi, eta, zeta
    real(wp) :: dn(3, 8), jm(3, 3), fx, fe, fz
    integer :: a
    do a = 1, 8
      fx = 1.0_wp + xi*XA(a)
      fe = 1.0_wp + eta*EA(a)
      fz = 1.0_wp + zeta*ZA(a)
      dn(1, a) = 0.125_wp*XA(a)*fe*fz
      dn(2, a) = 0.125_wp*EA(a)*fx*fz
      dn(3, a) = 0.125_wp*ZA(a)*fx*fe
    end do
    jm = matmul(dn, transpose(p))      ! jm(i, j) = d x_j / d xi_i
    det = triple(jm(:, 1), jm(:, 2), jm(:, 3))     ! det(jm') = det(jm)
  end function hex_jacobian

  !> a . (b x c)
  pure real(wp) function triple(a, b, c)
    real(wp), intent(in) :: a(3), b(3), c(3)
    triple = a(1)*(b(2)*c(3) - b(3)*c(2)) + a(2)*(b(3)*c(1) - b(1)*c(3)) + a(3)*(b(1)*c(2) - b(2)*c(1))
  end function triple

  !> Refuse two cells with the same nodes (in any order): a cell listed twice would count
  !! its stiffness twice. The cells are bucketed by their largest node (a counting sort, in
  !! cell order), so duplicates share a bucket, searched pair by pair (a large one sorted).
  !! The message names the first pair found in bucket order.
  subroutine check_duplicate_cells(mesh, err)
    type(mesh_t), intent(in) :: mesh
    type(error_t), intent(inout) :: err
    integer, parameter :: PAIRWISE = 32            ! larger buckets are sorted
    integer, allocatable :: key(:, :), first(:), members(:), perm(:)
    integer :: c, n, st, i, j, k, b, lo, hi, nb
    n = mesh%ncell
    if (n < 2) return
    allocate (key(8, n), first(mesh%nnode + 2), members(n), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory to check '//i2s(n)//' cells for duplicates')
      return
    end if
    key = 0
    first = 0
    do c = 1, n
      key(1:mesh%nvert, c) = mesh%cells(:, c)       ! a tetrahedron among hexahedra: 0s
      call sort_ints(key(:, c))
      first(key(8, c) + 2) = first(key(8, c) + 2) + 1
    end do
    first(1) = 1
    do k = 1, mesh%nnode + 1
      first(k + 1) = first(k + 1) + first(k)
    end do
    do c = 1, n                                     ! first(b + 1): the next free place of bucket b
      b = key(8, c)
      members(first(b + 1)) = c
      first(b + 1) = first(b + 1) + 1
    end do
    do b = 1, mesh%nnode
      lo = first(b)
      hi = first(b + 1) - 1
      nb = hi - lo + 1
      if (nb > PAIRWISE) then
        perm = members(lo:hi)
        call merge_sort_by_keys(perm, key)
        do i = 1, nb - 1
          if (all(key(:, perm(i)) == key(:, perm(i + 1)))) then
            call refuse(min(perm(i), perm(i + 1)), max(perm(i), perm(i + 1)))
            return
          end if
        end do
        cycle
      end if
      do i = lo, hi - 1
        do j = i + 1, hi
          if (all(key(:, members(i)) == key(:, members(j)))) then
            call refuse(members(i), members(j))
            return
          end if
        end do
      end do
    end do
  contains
    subroutine refuse(ci, cj)
      integer, intent(in) :: ci, cj
      call err%set(ERR_INPUT, 'elements '//i2s(mesh%cell_tag(ci))//' and '//i2s(mesh%cell_tag(cj))// &
                   ' have the same nodes: a cell listed twice would count its stiffness twice')
    end subroutine refuse
  end subroutine check_duplicate_cells

  ! ---- faces --------------------------------------------------------------------------------

  !> The nodes of local face f of cell c (counter-clockwise seen from outside): nv = 3 or 4,
  !! v(4) = 0 for a triangle.
  pure subroutine cell_face(mesh, c, f, v, nv)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: c, f
    integer, intent(out) :: v(4), nv
    if (mesh%cell_type(c) == ELEM_TET4) then
      nv = 3
      v(1:3) = mesh%cells(TET_FACE(:, f), c)
      v(4) = 0
    else
      nv = 4
      v = mesh%cells(HEX_FACE(:, f), c)
    end if
  end subroutine cell_face

  !> A face's key: its nodes sorted ascending, then 0 for a triangle.
  pure function face_key(v, nv) result(key)
    integer, intent(in) :: v(4), nv
    integer :: key(4)
    key = 0
    key(1:nv) = v(1:nv)
    call sort_ints(key(1:nv))
  end function face_key

  !> The 32-bit hash of a face key (each node folded in by a multiplicative mix whose products
  !! stay below 2**63).
  pure integer(i8) function key_hash(key) result(h)
    integer, intent(in) :: key(4)
    integer(i8), parameter :: low32 = 2_i8**32 - 1, mult = 73244475_i8
    integer :: i
    h = 0
    do i = 1, 4
      h = ieor(h, int(key(i), i8))
      h = iand(ieor(h, ishft(h, -16))*mult, low32)
    end do
    h = ieor(h, ishft(h, -16))
  end function key_hash

  !> The slot of the face of key `key` (hash h = key_hash(key)) in the table: where it is, or
  !! (an empty word) where it goes.
  integer(i8) function face_slot(faces, mesh, key, h) result(s)
    type(face_table_t), intent(in) :: faces
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: key(4)
    integer(i8), intent(in) :: h
    integer(i8) :: fp
    integer :: v(4), nv, c, f
    fp = ishft(h, -2)
    s = iand(h, faces%mask)
    do while (faces%v(s) /= 0)
      if (ishft(faces%v(s), -33) == fp) then
        call slot_face(faces, s, c, f)
        call cell_face(mesh, c, f, v, nv)
        if (all(face_key(v, nv) == key)) return
      end if
      s = iand(s + 1, faces%mask)
    end do
  end function face_slot

  !> The cell c and local face f of slot s (c = 0: empty).
  pure subroutine slot_face(faces, s, c, f)
    type(face_table_t), intent(in) :: faces
    integer(i8), intent(in) :: s
    integer, intent(out) :: c, f
    integer :: id
    id = int(iand(faces%v(s), FACE_BITS))
    c = (id - 1)/8 + 1
    f = id - 8*(c - 1)
    if (id == 0) c = 0
  end subroutine slot_face

  !> How many cells have the face of slot s: 0 (empty), 1 or 2.
  pure integer function slot_count(faces, s)
    type(face_table_t), intent(in) :: faces
    integer(i8), intent(in) :: s
    slot_count = int(iand(ishft(faces%v(s), -31), 3_i8))
  end function slot_count

  !> Hash every face of the body's cells (in cell order) and refuse cells that overlap across
  !! a face: with every cell positively oriented, the two cells of an inner face have it in
  !! opposite directions, so a face met twice in the same direction has two cells on one side
  !! (a node misplaced or a wrong node in a cell), and a face met a third time bounds three
  !! cells. The message names the cells of the first repeat in cell order.
  subroutine hash_faces(mesh, faces, err)
    type(mesh_t), intent(in) :: mesh
    type(face_table_t), intent(inout) :: faces
    type(error_t), intent(inout) :: err
    integer(i8) :: nf, cap, s, h
    integer :: c, f, nv, v(4), w(4), nw, key(4), st, c0, f0, p
    nf = 0
    do c = 1, mesh%ncell
      nf = nf + merge(4, 6, mesh%cell_type(c) == ELEM_TET4)
    end do
    if (8_i8*mesh%ncell > FACE_BITS) then
      call err%set(ERR_MEMORY, i2s(mesh%ncell)//' cells are more than the face table numbers (268435455)')
      return
    end if
    cap = 16
    do while (cap < 2*nf)
      cap = 2*cap
    end do
    allocate (faces%v(0:cap - 1), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for the '//i2s(int(nf))//' faces of '//i2s(mesh%ncell)//' cells')
      return
    end if
    faces%mask = cap - 1
    faces%v = 0
    do c = 1, mesh%ncell
      do f = 1, merge(4, 6, mesh%cell_type(c) == ELEM_TET4)
        call cell_face(mesh, c, f, v, nv)
        key = face_key(v, nv)
        h = key_hash(key)
        s = face_slot(faces, mesh, key, h)
        if (faces%v(s) == 0) then
          faces%v(s) = (8_i8*(c - 1) + f) + 2_i8**31 + ishft(ishft(h, -2), 33)
          cycle
        end if
        call slot_face(faces, s, c0, f0)
        if (slot_count(faces, s) == 2) then
          call err%set(ERR_INPUT, 'element '//i2s(mesh%cell_tag(c))//' has the face of nodes '//face_tags(mesh, v, nv)// &
                       ', which two other cells (element '//i2s(mesh%cell_tag(c0))//' and another) already '// &
                       'share: a face bounds at most two cells (cells overlap, or a node is wrong)')
          return
        end if
        ! the two cells' directions along the face: opposite, or the cells overlap
        call cell_face(mesh, c0, f0, w, nw)
        p = findloc(w(1:nw), v(1), dim=1)
        if (w(modulo(p - 2, nw) + 1) /= v(2)) then
          call err%set(ERR_INPUT, 'elements '//i2s(mesh%cell_tag(c0))//' and '//i2s(mesh%cell_tag(c))// &
                       ' overlap: both lie on the same side of their face of nodes '//face_tags(mesh, v, nv)// &
                       ' (a node misplaced or a wrong node in a cell)')
          return
        end if
        faces%v(s) = faces%v(s) + 2_i8**31      ! a second cell
      end do
    end do
  end subroutine hash_faces

  ! ---- groups -------------------------------------------------------------------------------

  !> One face group per physical surface (in the file's order of physical groups): its
  !! triangles and quadrangles that are boundary faces of the body (one cell has them),
  !! oriented as that cell has them (outward), and the nodes of those inside the body (two
  !! cells have them) as single nodes. Faces with a node outside the body are another
  !! body's; a face whose nodes are all the body's but which no cell has, and a face listed
  !! twice in a group, are bad input. Sets mesh%group (room for every physical surface,
  !! curve and point), mesh%ngroup and mesh%file_groups (the surfaces' names).
  subroutine face_groups(file_mesh, body_node, faces, mesh, err)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(face_table_t), intent(in) :: faces
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(inout) :: err
    integer, allocatable :: first(:), members(:), edges(:, :), cells(:), inner(:), seen_face(:)
    logical, allocatable :: marked(:)
    type(int_hash_t) :: seen
    integer :: phys, m, face, nv, v(4), w(4), nw, i, a, c, f, st, nedge, ninner, ngroup, nmax, nvf, seen_slot, key4(4)
    type(error_t) :: mem
    integer(i8) :: s, key
    type(text_buffer_t) :: names

    allocate (mesh%group(count(file_mesh%phys_dim(1:file_mesh%nphys) <= 2)))
    st = 0
    call group_members(file_mesh, 2, file_mesh%face_entity(1:file_mesh%nface), first, members, mem)
    nmax = 0
    if (.not. mem%failed()) then
      do phys = 1, file_mesh%nphys
        nmax = max(nmax, first(phys + 1) - first(phys))
      end do
      allocate (edges(4, nmax), cells(nmax), inner(mesh%nnode), marked(mesh%nnode), stat=st)
    end if
    if (st == 0 .and. .not. mem%failed()) call hash_init(seen, size(members), mem)
    if (st == 0 .and. .not. mem%failed()) allocate (seen_face(0:seen%mask), stat=st)
    if (st /= 0 .or. mem%failed()) then
      call err%set(ERR_MEMORY, 'not enough memory for the boundary faces')
      return
    end if
    marked = .false.
    ngroup = 0
    do phys = 1, file_mesh%nphys
      if (file_mesh%phys_dim(phys) /= 2) cycle
      call names%add(' '//file_mesh%phys_name(phys)%s)
      nedge = 0
      ninner = 0
      nvf = 3
      do m = first(phys), first(phys + 1) - 1
        face = members(m)
        nv = merge(4, 3, file_mesh%face_node(4, face) > 0)
        v = 0
        do i = 1, nv
          v(i) = body_node(file_mesh%face_node(i, face))
        end do
        if (any(v(1:nv) == 0)) cycle              ! another body's face
        key4 = face_key(v, nv)
        s = face_slot(faces, mesh, key4, key_hash(key4))
        ! the same face twice in the group: its load would count twice
        key = int(phys, i8)*(faces%mask + 1) + s
        seen_slot = hash_slot(seen, key)
        if (seen%key(seen_slot) == key) then
          call err%set(ERR_INPUT, 'elements '//i2s(file_mesh%face_tag(seen_face(seen_slot)))//' and '// &
                       i2s(file_mesh%face_tag(face))//" of physical surface '"//file_mesh%phys_name(phys)%s// &
                       "' are the same face (nodes "//face_tags(mesh, v, nv)//'): a face listed twice would apply its load twice')
          return
        end if
        seen%key(seen_slot) = key
        seen_face(seen_slot) = face
        if (faces%v(s) == 0) then               ! its nodes are the body's, but no cell has that face
          call err%set(ERR_INPUT, 'element '//i2s(file_mesh%face_tag(face))//" of physical surface '"// &
                       file_mesh%phys_name(phys)%s//"' (a "//trim(merge('quadrangle', 'triangle  ', nv == 4))// &
                       ' of nodes '//face_tags(mesh, v, nv)//') is not a face of any cell of the body: its condition or '// &
                       'load would be lost')
          return
        end if
        if (slot_count(faces, s) == 2) then     ! inside the body: its nodes, once each
          do i = 1, nv
            a = v(i)
            if (marked(a)) cycle
            marked(a) = .true.
            ninner = ninner + 1
            inner(ninner) = a
          end do
          cycle
        end if
        call slot_face(faces, s, c, f)
        call cell_face(mesh, c, f, w, nw)
        nedge = nedge + 1
        edges(:, nedge) = w
        cells(nedge) = c
        if (nw == 4) nvf = 4
      end do
      marked(inner(1:ninner)) = .false.
      if (nedge == 0 .and. ninner == 0) cycle
      ngroup = ngroup + 1
      mesh%group(ngroup)%name = file_mesh%phys_name(phys)%s
      mesh%group(ngroup)%nedge = nedge
      mesh%group(ngroup)%edge = edges(1:nvf, 1:nedge)
      mesh%group(ngroup)%cell = cells(1:nedge)
      mesh%group(ngroup)%nnode = ninner
      mesh%group(ngroup)%node = inner(1:ninner)
    end do
    call names%get(mesh%file_groups)
    mesh%file_groups = trim(adjustl(mesh%file_groups))
    mesh%ngroup = ngroup
  end subroutine face_groups

  !> The tags of the body nodes v(1:nv) of a face, 'a, b and c', for messages.
  function face_tags(mesh, v, nv) result(t)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: v(4), nv
    character(len=:), allocatable :: t
    integer :: i
    t = i2s(mesh%node_tag(v(1)))
    do i = 2, nv
      if (i == nv) then
        t = t//' and '//i2s(mesh%node_tag(v(i)))
      else
        t = t//', '//i2s(mesh%node_tag(v(i)))
      end if
    end do
  end function face_tags

  !> One node group per physical curve with lines of the body (both nodes the body's), after
  !! the face groups: their nodes, once each; a curve named as a surface adds its nodes to
  !! the surface's group. The curves' names go to file_groups.
  subroutine curve_groups(file_mesh, body_node, mesh, err)
    type(file_mesh_t), intent(in) :: file_mesh
    integer, intent(in) :: body_node(:)
    type(mesh_t), intent(inout) :: mesh
    type(error_t), intent(inout) :: err
    integer, allocatable :: first(:), members(:), nodes(:)
    logical, allocatable :: taken(:)
    integer :: phys, m, line, i, a, b, n, g, j, st
    type(error_t) :: mem
    character(len=:), allocatable :: names
    type(text_buffer_t) :: list

    st = 0
    call group_members(file_mesh, 1, file_mesh%line_entity(1:file_mesh%nline), first, members, mem)
    if (.not. mem%failed()) allocate (nodes(mesh%nnode), taken(mesh%nnode), stat=st)
    if (st /= 0 .or. mem%failed()) then
      call err%set(ERR_MEMORY, 'not enough memory for the physical curves')
      return
    end if
    taken = .false.
    do phys = 1, file_mesh%nphys
      if (file_mesh%phys_dim(phys) /= 1) cycle
      call list%add(' '//file_mesh%phys_name(phys)%s)
      n = 0
      do m = first(phys), first(phys + 1) - 1
        line = members(m)
        a = body_node(file_mesh%line_node(1, line))
        b = body_node(file_mesh%line_node(2, line))
        if (a == 0 .or. b == 0) cycle
        do i = 1, 2
          j = merge(a, b, i == 1)
          if (taken(j)) cycle
          taken(j) = .true.
          n = n + 1
          nodes(n) = j
        end do
      end do
      taken(nodes(1:n)) = .false.
      if (n == 0) cycle
      g = 0
      do j = 1, mesh%ngroup
        if (mesh%group(j)%name == file_mesh%phys_name(phys)%s) g = j
      end do
      if (g == 0) then
        mesh%ngroup = mesh%ngroup + 1
        g = mesh%ngroup
        mesh%group(g)%name = file_mesh%phys_name(phys)%s
        allocate (mesh%group(g)%edge(3, 0), mesh%group(g)%cell(0), mesh%group(g)%node(0))
      end if
      mesh%group(g)%node = [mesh%group(g)%node, nodes(1:n)]
      mesh%group(g)%nnode = size(mesh%group(g)%node)
    end do
    call list%get(names)
    if (len(names) == 0) return
    if (len(mesh%file_groups) == 0) mesh%file_groups = '(none)'
    mesh%file_groups = mesh%file_groups//'; physical curves:'//names
  end subroutine curve_groups

end module volume_topology
