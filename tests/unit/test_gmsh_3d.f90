!> Unit tests of the Gmsh reader in a 3D run (module gmsh_msh with volume_topology): MSH 4.1
!! files written here as text, from a small builder (nodes, physical groups, entities,
!! element blocks), and the shipped inputs/gmsh/blocks_3d.msh.
!!  - a unit cube of Kuhn tetrahedra and one of hexahedra (2 x 2 x 2 grid cells), one cell
!!    written inverted and the side faces in either direction: the cells positive (the
!!    inverted one turned back), volumes summing to 1, six face groups outward, their areas
!!    1 each, each face a face of its cell; assembled with rollers on three sides and a
!!    pressure on the fourth, the exact uniform-stress displacement (to 1e-12);
!!  - a mixed mesh (a hexahedron, a tetrahedron on half of one of its faces): ELEM_MIXED,
!!    nvert 8, the tetrahedron's 5th..8th vertices 0, groups of quadrangles and triangles
!!    (row 4 = 0), the pressure's resultant on a mixed group;
!!  - two physical volumes in one file read as two bodies, alone and together (msh_read_shared);
!!  - groups of nodes: a surface inside the body, a physical curve, physical points;
!!  - bad files, each refused naming the file, and the line or the element tag: a 3D
!!    second-order type, a prism, a face of a group not on the body, a missing node, a
!!    truncated file, a cell listed twice, overlapping cells, a degenerate tetrahedron, a
!!    twisted hexahedron, a face listed twice in a group, a tetrahedron on a surface entity,
!!    a 2D mesh, an unknown region, a region naming a surface, several volumes and no region.
!! With arguments, `test_gmsh_3d file.msh [region]` only reads that file and prints the time.
program test_gmsh_3d
  use kinds, only: wp
  use space, only: set_dimension
  use config, only: ELEM_HEX8, ELEM_TET4, ELEM_MIXED, body_cfg_t, boundary_cfg_t, traction_cfg_t
  use mesh, only: mesh_t, group_index, group_nodes, nodes_only, nodes_only_refusal, file_cells
  use gmsh_msh, only: msh_read, msh_read_shared
  use errors, only: error_t, ERR_INPUT
  use strings, only: i2s
  use elements_3d, only: kuhn_tets, face_area_normal, tet4_gradients, hex8_gradients
  use assembly, only: assemble_body, body_system_t
  use testing, only: report, report_le, test_summary, write_file, solve_full
  implicit none (type, external)

  integer, parameter :: LW = 160
  !> a mesh file being written: nodes, physical groups, entities, element blocks
  type :: block_t
    integer :: dim = 0, ent = 0, etype = 0, n = 0
    integer, allocatable :: tag(:), nodes(:, :)      ! (10, n)
  end type block_t
  type :: builder_t
    integer :: nn = 0, nphys = 0, nent = 0, nblock = 0, next_tag = 0
    real(wp), allocatable :: x(:, :)
    integer, allocatable :: ntag(:)
    integer, allocatable :: pdim(:), ptag(:), edim(:), etag(:), ephys(:)
    character(len=40), allocatable :: pname(:)
    type(block_t), allocatable :: blk(:)
  end type builder_t

  character(len=:), allocatable :: tmp
  character(len=256) :: arg

  call set_dimension(3)
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    call bench(trim(arg))
    stop
  end if
  call get_environment_variable('BUILD', arg)
  if (len_trim(arg) == 0) arg = 'build/release'
  tmp = trim(arg)//'/test_gmsh_3d_'

  call test_cube(.true.)
  call test_cube(.false.)
  call test_mixed()
  call test_two_volumes()
  call test_node_groups()
  call test_bad_files()
  call test_shipped()
  call test_summary()

contains

  ! ---- the builder ------------------------------------------------------------------------

  subroutine start(b)
    type(builder_t), intent(out) :: b
    allocate (b%x(3, 0), b%ntag(0), b%pdim(0), b%ptag(0), b%pname(0), b%edim(0), b%etag(0), b%ephys(0), &
              b%blk(0))
  end subroutine start

  !> A node at (x, y, z), tag `tag` (default: the next number); returns its tag.
  integer function node(b, x, y, z, tag)
    type(builder_t), intent(inout) :: b
    real(wp), intent(in) :: x, y, z
    integer, intent(in), optional :: tag
    b%nn = b%nn + 1
    node = b%nn
    if (present(tag)) node = tag
    b%x = reshape([b%x, [x, y, z]], [3, b%nn])
    b%ntag = [b%ntag, node]
  end function node

  !> A physical group (dim, tag, name) and one entity (dim, tag = the group's tag) in it.
  subroutine group(b, dim, tag, name)
    type(builder_t), intent(inout) :: b
    integer, intent(in) :: dim, tag
    character(len=*), intent(in) :: name
    b%nphys = b%nphys + 1
    b%pdim = [b%pdim, dim]
    b%ptag = [b%ptag, tag]
    b%pname = [character(len=40) :: b%pname, name]
    b%nent = b%nent + 1
    b%edim = [b%edim, dim]
    b%etag = [b%etag, tag]
    b%ephys = [b%ephys, tag]
  end subroutine group

  !> An element of type etype on entity (dim, ent): appended to the last block if it is of
  !! the same entity and type, else in a new block. Returns its tag.
  integer function elem(b, dim, ent, etype, nodes) result(t)
    type(builder_t), intent(inout) :: b
    integer, intent(in) :: dim, ent, etype, nodes(:)
    type(block_t), allocatable :: tmpb(:)
    integer :: k, j
    k = b%nblock
    if (k > 0) then
      if (b%blk(k)%dim /= dim .or. b%blk(k)%ent /= ent .or. b%blk(k)%etype /= etype) k = 0
    end if
    if (k == 0) then
      allocate (tmpb(b%nblock + 1))
      tmpb(1:b%nblock) = b%blk
      call move_alloc(tmpb, b%blk)
      b%nblock = b%nblock + 1
      k = b%nblock
      b%blk(k)%dim = dim
      b%blk(k)%ent = ent
      b%blk(k)%etype = etype
      allocate (b%blk(k)%tag(0), b%blk(k)%nodes(10, 0))
    end if
    b%next_tag = b%next_tag + 1
    t = b%next_tag
    b%blk(k)%n = b%blk(k)%n + 1
    b%blk(k)%tag = [b%blk(k)%tag, t]
    b%blk(k)%nodes = reshape([b%blk(k)%nodes, [nodes, (0, j=size(nodes) + 1, 10)]], [10, b%blk(k)%n])
  end function elem

  !> The file's lines.
  function text(b) result(l)
    type(builder_t), intent(in) :: b
    character(len=LW), allocatable :: l(:)
    character(len=LW) :: s
    integer :: k, j, d, nv, cnt(0:3)
    l = [character(len=LW) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', '$PhysicalNames']
    write (s, '(i0)') b%nphys
    l = [l, s]
    do k = 1, b%nphys
      write (s, '(i0,1x,i0,a)') b%pdim(k), b%ptag(k), ' "'//trim(b%pname(k))//'"'
      l = [l, s]
    end do
    l = [character(len=LW) :: l, '$EndPhysicalNames', '$Entities']
    cnt = [(count(b%edim == d), d=0, 3)]
    write (s, '(4(i0,1x))') cnt
    l = [l, s]
    do d = 0, 3
      do k = 1, b%nent
        if (b%edim(k) /= d) cycle
        if (d == 0) then
          write (s, '(i0,a,i0)') b%etag(k), ' 0 0 0 1 ', b%ephys(k)
        else
          write (s, '(i0,a,i0,a)') b%etag(k), ' 0 0 0 1 1 1 1 ', b%ephys(k), ' 0'
        end if
        l = [l, s]
      end do
    end do
    l = [character(len=LW) :: l, '$EndEntities', '$Nodes']
    write (s, '(a,i0,1x,i0,1x,i0)') '1 ', b%nn, minval(b%ntag), maxval(b%ntag)
    l = [l, s]
    write (s, '(a,i0)') '3 1 0 ', b%nn
    l = [l, s]
    do k = 1, b%nn
      write (s, '(i0)') b%ntag(k)
      l = [l, s]
    end do
    do k = 1, b%nn
      write (s, '(3(es24.16e3,1x))') b%x(:, k)
      l = [l, s]
    end do
    l = [character(len=LW) :: l, '$EndNodes', '$Elements']
    write (s, '(i0,1x,i0,a,i0)') b%nblock, b%next_tag, ' 1 ', b%next_tag
    l = [l, s]
    do k = 1, b%nblock
      write (s, '(4(i0,1x))') b%blk(k)%dim, b%blk(k)%ent, b%blk(k)%etype, b%blk(k)%n
      l = [l, s]
      nv = count(b%blk(k)%nodes(:, 1) > 0)
      do j = 1, b%blk(k)%n
        write (s, '(11(i0,1x))') b%blk(k)%tag(j), b%blk(k)%nodes(1:nv, j)
        l = [l, s]
      end do
    end do
    l = [character(len=LW) :: l, '$EndElements']
  end function text

  !> The number (1-based) of the first line of `l` that is `s`, 0 if none.
  integer function line_of(l, s)
    character(len=*), intent(in) :: l(:), s
    do line_of = 1, size(l)
      if (trim(l(line_of)) == trim(s)) return
    end do
    line_of = 0
  end function line_of

  ! ---- geometry of a read mesh ----------------------------------------------------------------

  !> The smallest Jacobian determinant of cell c (a tetrahedron's 6 V; a hexahedron's at its
  !! 8 corners) and its volume.
  subroutine cell_measure(m, c, jmin, vol)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: c
    real(wp), intent(out) :: jmin, vol
    real(wp), parameter :: g = 0.577350269189625764509148780502_wp
    real(wp) :: xe(3, 8), gr(3, 8), nf(8), det
    integer :: a, i, j, k
    xe = 0.0_wp
    if (m%cell_type(c) == ELEM_TET4) then
      do a = 1, 4
        xe(:, a) = m%xy(:, m%cells(a, c))
      end do
      call tet4_gradients(xe(:, 1:4), gr(:, 1:4), det)
      jmin = det
      vol = det/6.0_wp
      return
    end if
    do a = 1, 8
      xe(:, a) = m%xy(:, m%cells(a, c))
    end do
    jmin = huge(1.0_wp)
    vol = 0.0_wp
    do k = -1, 1, 2
      do j = -1, 1, 2
        do i = -1, 1, 2
          call hex8_gradients(xe, real(i, wp), real(j, wp), real(k, wp), nf, gr, det)
          jmin = min(jmin, det)
          call hex8_gradients(xe, i*g, j*g, k*g, nf, gr, det)
          vol = vol + det
        end do
      end do
    end do
  end subroutine cell_measure

  !> Group `name`: its faces' largest deviation of the unit outward normal from `normal`,
  !! their total area, their number, and whether each face's nodes are nodes of its cell.
  subroutine group_faces(m, name, normal, dev, area, nface, on_cell)
    type(mesh_t), intent(in) :: m
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: normal(3)
    real(wp), intent(out) :: dev, area
    integer, intent(out) :: nface
    logical, intent(out) :: on_cell
    real(wp) :: xf(3, 4), an(3)
    integer :: g, e, nv, a
    dev = huge(1.0_wp)
    area = 0.0_wp
    nface = 0
    on_cell = .false.
    g = group_index(m, name)
    if (g == 0) return
    dev = 0.0_wp
    on_cell = .true.
    nface = m%group(g)%nedge
    do e = 1, nface
      nv = count(m%group(g)%edge(:, e) > 0)
      xf = 0.0_wp
      do a = 1, nv
        xf(:, a) = m%xy(:, m%group(g)%edge(a, e))
        on_cell = on_cell .and. any(m%cells(:, m%group(g)%cell(e)) == m%group(g)%edge(a, e))
      end do
      call face_area_normal(nv, xf, an)
      area = area + norm2(an)
      dev = max(dev, norm2(an/norm2(an) - normal))
    end do
  end subroutine group_faces

  !> Read, reporting failure with the message.
  subroutine read_ok(path, region, m, what)
    character(len=*), intent(in) :: path, region, what
    type(mesh_t), intent(out) :: m
    type(error_t) :: err
    call msh_read(path, region, 1, m, err)
    call report(.not. err%failed(), what//': read')
    if (err%failed()) write (*, '(a)') '      msg: '//err%text()
  end subroutine read_ok

  !> Write `lines`, read it as body 2 and check that the refusal is bad input naming the body,
  !! the file and every key.
  subroutine expect_error(name, lines, region, keys, what)
    character(len=*), intent(in) :: name, lines(:), region, keys(:), what
    type(mesh_t) :: m
    type(error_t) :: err
    integer :: k, u
    logical :: has
    character(len=:), allocatable :: msg
    call write_file(tmp//name, lines)
    call msh_read(tmp//name, region, 2, m, err)
    msg = err%text()
    has = index(msg, tmp//name) > 0 .and. index(msg, 'body 2') > 0
    do k = 1, size(keys)
      has = has .and. index(msg, trim(keys(k))) > 0
    end do
    call report(err%failed() .and. err%category == ERR_INPUT .and. has, what)
    write (*, '(a)') '      msg: '//msg
    open (newunit=u, file=tmp//name)
    close (u, status='delete')
  end subroutine expect_error

  ! ---- the cube ---------------------------------------------------------------------------------

  !> The unit cube on an n x n x n grid: physical volume 'cube' (tag 1), the six sides
  !! x0, x1, y0, y1, z0, z1 (tags 11..16), the side faces written in the grid's (p, q) order
  !! whatever their orientation, tetrahedra (Kuhn) or hexahedra; cell `inverted` written
  !! inverted (0: none). `first` returns the cells' tags' first and `good` the inverted cell's
  !! node tags in positive order.
  subroutine cube(b, n, tets, inverted, first, good)
    type(builder_t), intent(out) :: b
    integer, intent(in) :: n, inverted
    logical, intent(in) :: tets
    integer, intent(out) :: first, good(8)
    integer :: i, j, k, v(8), t(4, 6), s, a, q, fixed, p1, p2, c(4), ijk(3), e, side
    character(len=2), parameter :: side_name(6) = ['x0', 'x1', 'y0', 'y1', 'z0', 'z1']
    call start(b)
    do k = 0, n
      do j = 0, n
        do i = 0, n
          e = node(b, real(i, wp)/n, real(j, wp)/n, real(k, wp)/n)
        end do
      end do
    end do
    call group(b, 3, 1, 'cube')
    do s = 1, 6
      call group(b, 2, 10 + s, side_name(s))
    end do
    ! the sides first (lower element tags), then the cells
    do side = 1, 6
      fixed = (side + 1)/2
      p1 = merge(2, 1, fixed == 1)
      p2 = merge(2, 3, fixed == 3)
      do q = 0, n - 1
        do a = 0, n - 1
          ijk(fixed) = merge(0, n, mod(side, 2) == 1)
          ijk(p1) = a
          ijk(p2) = q
          c(1) = gid(n, ijk)
          ijk(p1) = a + 1
          c(2) = gid(n, ijk)
          ijk(p2) = q + 1
          c(3) = gid(n, ijk)
          ijk(p1) = a
          c(4) = gid(n, ijk)
          if (tets) then   ! the cut from the lowest to the highest corner, as the Kuhn split's
            e = elem(b, 2, 10 + side, 2, c([1, 2, 3]))
            e = elem(b, 2, 10 + side, 2, c([1, 3, 4]))
          else
            e = elem(b, 2, 10 + side, 3, c)
          end if
        end do
      end do
    end do
    first = b%next_tag + 1
    good = 0
    do k = 0, n - 1
      do j = 0, n - 1
        do i = 0, n - 1
          v = [gid(n, [i, j, k]), gid(n, [i + 1, j, k]), gid(n, [i + 1, j + 1, k]), gid(n, [i, j + 1, k]), &
               gid(n, [i, j, k + 1]), gid(n, [i + 1, j, k + 1]), gid(n, [i + 1, j + 1, k + 1]), gid(n, [i, j + 1, k + 1])]
          if (tets) then
            call kuhn_tets(v, t)
            do s = 1, 6
              if (b%next_tag + 1 - first + 1 == inverted) then
                good(1:4) = t(:, s)
                e = elem(b, 3, 1, 4, t([1, 3, 2, 4], s))
              else
                e = elem(b, 3, 1, 4, t(:, s))
              end if
            end do
          else if (b%next_tag + 1 - first + 1 == inverted) then
            good = v
            e = elem(b, 3, 1, 5, v([1, 4, 3, 2, 5, 8, 7, 6]))
          else
            e = elem(b, 3, 1, 5, v)
          end if
        end do
      end do
    end do
  end subroutine cube

  !> The node of grid point g of an n x n x n grid (1 + i + (n + 1)(j + (n + 1) k)).
  pure integer function gid(n, g)
    integer, intent(in) :: n, g(3)
    gid = 1 + g(1) + (n + 1)*(g(2) + (n + 1)*g(3))
  end function gid

  !> The unit cube of tetrahedra or hexahedra: cells, groups, the inverted cell turned, and a
  !! patch test through the assembly.
  subroutine test_cube(tets)
    logical, intent(in) :: tets
    type(builder_t) :: b
    type(mesh_t) :: m
    character(len=LW), allocatable :: l(:)
    character(len=:), allocatable :: what, path
    integer :: first, good(8), c, s, nf, nneg, ninv, seen(200)
    real(wp) :: jmin, vol, total, dev, area, worst_dev, worst_area
    logical :: on_cell, all_on
    real(wp), parameter :: normals(3, 6) = reshape([-1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1], [3, 6])
    character(len=2), parameter :: side_name(6) = ['x0', 'x1', 'y0', 'y1', 'z0', 'z1']

    what = merge('cube of tetrahedra', 'cube of hexahedra ', tets)
    what = trim(what)
    call cube(b, 2, tets, 5, first, good)
    l = text(b)
    path = tmp//merge('cube_tet.msh', 'cube_hex.msh', tets)
    call write_file(path, l)
    call read_ok(path, '', m, what)
    if (m%ncell == 0) return
    call report(m%nnode == 27 .and. m%ncell == merge(48, 8, tets) .and. m%element == merge(ELEM_TET4, ELEM_HEX8, tets) &
                .and. m%nvert == merge(4, 8, tets) .and. size(m%xy, 1) == 3 .and. .not. m%structured .and. &
                .not. m%box .and. m%source == path, what//': 27 nodes, '//i2s(merge(48, 8, tets))//' cells, '// &
                trim(merge('ELEM_TET4', 'ELEM_HEX8', tets))//', from the file')
    total = 0.0_wp
    nneg = 0
    ninv = 0
    do c = 1, m%ncell
      call cell_measure(m, c, jmin, vol)
      if (.not. jmin > 0.0_wp) nneg = nneg + 1
      total = total + vol
      if (m%cell_tag(c) == first + 4) then
        if (all(m%node_tag(m%cells(:, c)) == good(1:m%nvert))) ninv = ninv + 1
      end if
    end do
    call report(nneg == 0, what//': every cell positively oriented (Jacobian > 0 at every corner)')
    call report_le(abs(total - 1.0_wp), 1.0e-14_wp, what//': the volumes sum to 1')
    call report(ninv == 1, what//': the cell written inverted is turned (first vertex kept): '// &
                'its nodes in positive order')
    worst_dev = 0.0_wp
    worst_area = 0.0_wp
    all_on = .true.
    nf = 0
    do s = 1, 6
      call group_faces(m, side_name(s), real(normals(:, s), wp), dev, area, c, on_cell)
      worst_dev = max(worst_dev, dev)
      worst_area = max(worst_area, abs(area - 1.0_wp))
      all_on = all_on .and. on_cell .and. c == merge(8, 4, tets)
      nf = nf + c
    end do
    call report(m%ngroup == 6 .and. all_on, what//': six face groups of '//i2s(merge(8, 4, tets))// &
                ' faces, each face a face of its cell')
    call report_le(worst_dev, 1.0e-14_wp, what//': every group face outward (normal of its side)')
    call report_le(worst_area, 1.0e-14_wp, what//': each side''s faces sum to area 1')
    call report(size(m%group(1)%edge, 1) == merge(3, 4, tets), what//': face rows '//i2s(merge(3, 4, tets)))
    ! locality: permutations, and the file's cells back
    seen = 0
    seen(m%file_node) = 1
    call report(size(m%file_node) == 27 .and. all(seen(1:27) == 1) .and. size(m%file_cell) == m%ncell, &
                what//': numbered for locality (file_node, file_cell permutations)')
    call patch(m, what)
    call delete(path)
  end subroutine test_cube

  !> Rollers on x0 (ux), y0 (uy) and z0 (uz), pressure p on y1: the exact displacement
  !! u = (nu p x, -p y, nu p z) / E, to 1e-12 of its size.
  subroutine patch(m, what)
    type(mesh_t), intent(in) :: m
    character(len=*), intent(in) :: what
    type(body_cfg_t) :: body
    type(boundary_cfg_t) :: bnd(3)
    type(traction_cfg_t) :: tr(1)
    type(body_system_t) :: sys
    type(error_t) :: err
    real(wp), allocatable :: u(:)
    real(wp) :: ex(3), e
    real(wp), parameter :: p = 1.0e6_wp, young = 2.1e11_wp, nu = 0.3_wp
    integer :: k, info
    character(len=2), parameter :: names(3) = ['x0', 'y0', 'z0']
    body%id = 1
    body%young = young
    body%poisson = nu
    do k = 1, 3
      bnd(k)%body = 1
      bnd(k)%group = names(k)
      bnd(k)%fix = .false.
      bnd(k)%fix(k) = .true.
      bnd(k)%u = 0.0_wp
    end do
    tr(1)%body = 1
    tr(1)%group = 'y1'
    tr(1)%pressure = p
    call assemble_body(m, body, .true., tr, 1, sys, err, boundaries=bnd)
    info = merge(1, 0, err%failed())
    call report(info == 0 .and. sys%nrig == 0, what//': assembled (rollers on three sides, no rigid motion left)')
    if (info /= 0) then
      write (*, '(a)') '      msg: '//err%text()
      return
    end if
    call report_le(maxval(abs(sum(reshape(sys%f_applied, [3, m%nnode]), dim=2) - [0.0_wp, -p, 0.0_wp]))/p, &
                   1.0e-14_wp, what//': the pressure''s resultant on y1 is (0, -p, 0)')
    call solve_full(sys, info, err%text(), what, u)
    e = 0.0_wp
    do k = 1, m%nnode
      ex = [nu*p*m%xy(1, k), -p*m%xy(2, k), nu*p*m%xy(3, k)]/young
      e = max(e, maxval(abs(u(3*k - 2:3*k) - ex)))
    end do
    call report_le(e/(p/young), 1.0e-12_wp, what//': patch test, the uniform-stress displacement exact')
  end subroutine patch

  ! ---- mixed, two volumes, node groups ----------------------------------------------------------

  !> A hexahedron [0,1]^3 (its nodes 1..8) and a tetrahedron on the triangle (1,0,0),
  !! (1,1,0), (1,0,1) of its side x = 1, apex (2,0,0): volume 7/6. Groups 'y0' and 'z0'
  !! hold a quadrangle of the hexahedron and a triangle of the tetrahedron.
  subroutine test_mixed()
    type(builder_t) :: b
    type(mesh_t) :: m
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(1)
    type(boundary_cfg_t) :: bnd(1)
    type(body_system_t) :: sys
    type(error_t) :: err
    integer :: e, k, c, ntet, nf, g
    real(wp) :: jmin, vol, total, dev, area
    logical :: on_cell, tri_row4
    integer, allocatable :: fc(:, :)
    call start(b)
    e = node(b, 0.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 1.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 1.0_wp, 1.0_wp, 0.0_wp)
    e = node(b, 0.0_wp, 1.0_wp, 0.0_wp)
    e = node(b, 0.0_wp, 0.0_wp, 1.0_wp)
    e = node(b, 1.0_wp, 0.0_wp, 1.0_wp)
    e = node(b, 1.0_wp, 1.0_wp, 1.0_wp)
    e = node(b, 0.0_wp, 1.0_wp, 1.0_wp)
    e = node(b, 2.0_wp, 0.0_wp, 0.0_wp)
    call group(b, 3, 1, 'solid')
    call group(b, 2, 2, 'y0')
    call group(b, 2, 3, 'z0')
    call group(b, 2, 4, 'x0')
    e = elem(b, 2, 2, 3, [1, 2, 6, 5])
    e = elem(b, 2, 2, 2, [2, 9, 6])
    e = elem(b, 2, 3, 3, [1, 2, 3, 4])
    e = elem(b, 2, 3, 2, [2, 3, 9])
    e = elem(b, 2, 4, 3, [1, 4, 8, 5])
    e = elem(b, 3, 1, 5, [1, 2, 3, 4, 5, 6, 7, 8])
    e = elem(b, 3, 1, 4, [2, 3, 6, 9])
    call write_file(tmp//'mixed.msh', text(b))
    call read_ok(tmp//'mixed.msh', 'solid', m, 'mixed hexahedron and tetrahedron')
    if (m%ncell == 0) return
    ntet = 0
    total = 0.0_wp
    do c = 1, m%ncell
      call cell_measure(m, c, jmin, vol)
      total = total + vol
      if (m%cell_type(c) == ELEM_TET4) then
        ntet = ntet + 1
        if (any(m%cells(5:8, c) /= 0) .or. .not. jmin > 0.0_wp) ntet = -99
      end if
    end do
    call report(m%element == ELEM_MIXED .and. m%nvert == 8 .and. m%ncell == 2 .and. ntet == 1 .and. &
                count(m%cell_type == ELEM_HEX8) == 1, 'mixed: ELEM_MIXED, nvert 8, a tetrahedron with 0 in '// &
                'rows 5..8, positive')
    call report_le(abs(total - 7.0_wp/6.0_wp), 1.0e-14_wp, 'mixed: the volumes sum to 7/6')
    call group_faces(m, 'y0', [0.0_wp, -1.0_wp, 0.0_wp], dev, area, nf, on_cell)
    g = group_index(m, 'y0')
    tri_row4 = .false.
    if (g > 0) then
      tri_row4 = size(m%group(g)%edge, 1) == 4 .and. count(m%group(g)%edge(4, :) == 0) == 1
    end if
    call report(nf == 2 .and. on_cell .and. tri_row4 .and. dev < 1.0e-14_wp .and. abs(area - 1.5_wp) < 1e-14_wp, &
                'mixed: group y0, a quadrangle and a triangle (row 4 = 0), outward, area 1.5')
    call group_faces(m, 'z0', [0.0_wp, 0.0_wp, -1.0_wp], dev, area, nf, on_cell)
    call report(nf == 2 .and. on_cell .and. dev < 1.0e-14_wp .and. abs(area - 1.5_wp) < 1e-14_wp, &
                'mixed: group z0, outward, area 1.5')
    fc = file_cells(m)
    call report(all(fc(:, 1) == [(k, k=1, 8)]) .and. all(fc(1:4, 2) == [2, 3, 6, 9]) .and. all(fc(5:8, 2) == 0), &
                'mixed: file_cells gives back the file''s cells')
    ! the assembly takes a mixed solid mesh: a pressure on the mixed group y0
    body%id = 1
    bnd(1)%body = 1
    bnd(1)%group = 'x0'
    bnd(1)%fix = .true.
    tr(1)%body = 1
    tr(1)%group = 'y0'
    tr(1)%pressure = 2.0_wp
    call assemble_body(m, body, .true., tr, 1, sys, err, boundaries=bnd)
    call report(.not. err%failed(), 'mixed: assembled')
    if (err%failed()) then
      write (*, '(a)') '      msg: '//err%text()
    else
      call report_le(maxval(abs(sum(reshape(sys%f_applied, [3, m%nnode]), dim=2) - [0.0_wp, 3.0_wp, 0.0_wp])), &
                     1.0e-14_wp, 'mixed: the pressure 2 on y0 (area 1.5) has resultant (0, 3, 0)')
    end if
    call delete(tmp//'mixed.msh')
  end subroutine test_mixed

  !> Two unit cubes of hexahedra (each 2 x 2 x 2), 'low' and 'high' (on top, y from 1 to 2,
  !! its own nodes), in one file: each read by its region, read together the same; no region
  !! is refused naming both.
  subroutine test_two_volumes()
    type(builder_t) :: b
    type(mesh_t) :: lo, hi
    type(mesh_t) :: both(2)
    type(error_t) :: errs(2), err
    integer :: i, j, k, e, body, base, g
    real(wp) :: dev, area
    integer :: nf
    logical :: on_cell, same
    call start(b)
    call group(b, 3, 1, 'low')
    call group(b, 3, 2, 'high')
    call group(b, 2, 3, 'low_top')
    call group(b, 2, 4, 'high_bottom')
    do body = 1, 2
      base = b%nn
      do k = 0, 2
        do j = 0, 2
          do i = 0, 2
            e = node(b, 0.5_wp*i, 0.5_wp*j + (body - 1), 0.5_wp*k)
          end do
        end do
      end do
      do k = 0, 1
        do i = 0, 1
          j = merge(2, 0, body == 1)     ! the top of 'low', the bottom of 'high'
          e = elem(b, 2, 2 + body, 3, base + [gid(2, [i, j, k]), gid(2, [i + 1, j, k]), gid(2, [i + 1, j, k + 1]), &
                                              gid(2, [i, j, k + 1])])
        end do
      end do
      do k = 0, 1
        do j = 0, 1
          do i = 0, 1
            e = elem(b, 3, body, 5, base + [gid(2, [i, j, k]), gid(2, [i + 1, j, k]), gid(2, [i + 1, j + 1, k]), &
                                            gid(2, [i, j + 1, k]), gid(2, [i, j, k + 1]), gid(2, [i + 1, j, k + 1]), &
                                            gid(2, [i + 1, j + 1, k + 1]), gid(2, [i, j + 1, k + 1])])
          end do
        end do
      end do
    end do
    call write_file(tmp//'two.msh', text(b))
    call read_ok(tmp//'two.msh', 'low', lo, 'two volumes: low')
    call read_ok(tmp//'two.msh', 'high', hi, 'two volumes: high')
    call report(lo%nnode == 27 .and. hi%nnode == 27 .and. lo%ncell == 8 .and. hi%ncell == 8 .and. &
                minval(hi%node_tag) == 28 .and. maxval(lo%node_tag) == 27 .and. lo%y0 == 0.0_wp .and. &
                hi%y0 == 1.0_wp, 'two volumes: two bodies of 27 nodes and 8 cells each, their own nodes')
    call group_faces(lo, 'low_top', [0.0_wp, 1.0_wp, 0.0_wp], dev, area, nf, on_cell)
    call report(nf == 4 .and. on_cell .and. dev < 1e-14_wp .and. abs(area - 1) < 1e-14_wp .and. &
                group_index(lo, 'high_bottom') == 0, 'two volumes: low_top on low, normal +y, area 1 (no high_bottom)')
    call group_faces(hi, 'high_bottom', [0.0_wp, -1.0_wp, 0.0_wp], dev, area, nf, on_cell)
    call report(nf == 4 .and. on_cell .and. dev < 1e-14_wp .and. abs(area - 1) < 1e-14_wp, &
                'two volumes: high_bottom on high, normal -y, area 1')
    call report(index(lo%file_groups, 'low_top') > 0 .and. index(lo%file_groups, 'high_bottom') > 0, &
                'two volumes: file_groups lists every physical surface: '//lo%file_groups)
    call msh_read_shared(tmp//'two.msh', [character(len=8) :: 'low', 'high'], [1, 2], both, errs, 2)
    same = .not. errs(1)%failed() .and. .not. errs(2)%failed()
    if (same) same = all(both(1)%xy == lo%xy) .and. all(both(1)%cells == lo%cells) .and. &
                     all(both(2)%xy == hi%xy) .and. all(both(2)%cells == hi%cells) .and. &
                     both(1)%ngroup == lo%ngroup .and. both(2)%ngroup == hi%ngroup
    if (same) then
      do g = 1, lo%ngroup
        same = same .and. all(both(1)%group(g)%edge == lo%group(g)%edge)
      end do
    end if
    call report(same, 'two volumes: read together (msh_read_shared) = read one by one')
    call msh_read(tmp//'two.msh', '', 1, lo, err)
    call report(err%failed() .and. index(err%text(), "2 physical volumes ('low', 'high')") > 0, &
                'two volumes: no region is refused, naming both volumes')
    write (*, '(a)') '      msg: '//err%text()
    call delete(tmp//'two.msh')
  end subroutine test_two_volumes

  !> Groups of nodes on the tetrahedral cube (2 x 2 x 2): 'mid', a physical surface of one
  !! inner face (the triangle of nodes 1, 2, 14, shared by two tetrahedra); 'edge', a physical
  !! curve along y = 0, z = 0; 'corner', a physical point on node 27; 'x0' also a physical
  !! curve name (its nodes join the face group).
  subroutine test_node_groups()
    type(builder_t) :: b
    type(mesh_t) :: m
    integer :: first, good(8), e, g
    integer, allocatable :: nodes(:)
    character(len=:), allocatable :: s
    call cube(b, 2, .true., 0, first, good)
    ! node ids: 1 + i + 3 (j + 3 k); 1 = (0,0,0), 14 = (1,1,1)/2, 27 = (1,1,1)
    call group(b, 2, 20, 'mid')
    e = elem(b, 2, 20, 2, [1, 2, 14])      ! the Kuhn tetrahedra (1,2,5,14) and (1,2,11,14) share it
    call group(b, 1, 21, 'edge')
    e = elem(b, 1, 21, 1, [1, 2])
    e = elem(b, 1, 21, 1, [2, 3])
    call group(b, 0, 22, 'corner')
    e = elem(b, 0, 22, 15, [27])
    call group(b, 1, 23, 'x0')
    e = elem(b, 1, 23, 1, [1, 4])
    call write_file(tmp//'nodes.msh', text(b))
    call read_ok(tmp//'nodes.msh', 'cube', m, 'node groups')
    if (m%ncell == 0) return
    g = group_index(m, 'mid')
    call report(g > 0, "node groups: the inner surface 'mid' is a group")
    if (g > 0) then
      call group_nodes(m, g, nodes)
      call report(nodes_only(m, g) .and. .not. m%group(g)%point .and. size(nodes) == 3, &
                  "'mid': the three nodes of an inner face, no face")
      if (size(nodes) == 3) call report(all(sorted(m%node_tag(nodes)) == [1, 2, 14]), "'mid': nodes 1, 2, 14")
      call nodes_only_refusal(m, g, 'contact needs', s)
      call report(index(s, "'mid' has no face on the boundary") > 0 .and. index(s, 'a surface on the boundary') > 0, &
                  'an inner surface is refused for contact: '//s)
    end if
    g = group_index(m, 'edge')
    call report(g > 0, "node groups: the physical curve 'edge' is a group")
    if (g > 0) then
      call group_nodes(m, g, nodes)
      call report(nodes_only(m, g) .and. size(nodes) == 3, "'edge': its 3 nodes, no face")
      if (size(nodes) == 3) call report(all(sorted(m%node_tag(nodes)) == [1, 2, 3]), "'edge': nodes 1, 2, 3")
    end if
    g = group_index(m, 'corner')
    call report(g > 0, "node groups: the physical point 'corner' is a group")
    if (g > 0) then
      call group_nodes(m, g, nodes)
      call report(m%group(g)%point .and. size(nodes) == 1, "'corner': one node")
      if (size(nodes) == 1) call report(m%node_tag(nodes(1)) == 27, "'corner': node 27")
      call nodes_only_refusal(m, g, 'a traction needs', s)
      call report(index(s, "'corner' is a physical point: a traction needs a surface") > 0, &
                  'a point is refused for a traction: '//s)
    end if
    g = group_index(m, 'x0')
    if (g > 0) call group_nodes(m, g, nodes)
    call report(g > 0 .and. m%group(g)%nedge == 8 .and. m%group(g)%nnode == 2 .and. size(nodes) == 9, &
                "the curve named as the face group 'x0' adds its nodes to it")
    call report(index(m%file_groups, 'physical curves: edge x0') > 0 .and. &
                index(m%file_groups, 'physical points: corner') > 0, 'file_groups: '//m%file_groups)
    call delete(tmp//'nodes.msh')
  end subroutine test_node_groups

  pure function sorted(v) result(w)
    integer, intent(in) :: v(:)
    integer :: w(size(v)), i, j, x
    w = v
    do i = 2, size(w)
      x = w(i)
      j = i - 1
      do while (j >= 1)
        if (w(j) <= x) exit
        w(j + 1) = w(j)
        j = j - 1
      end do
      w(j + 1) = x
    end do
  end function sorted

  ! ---- bad files --------------------------------------------------------------------------------

  subroutine test_bad_files()
    type(builder_t) :: b, b0
    character(len=LW), allocatable :: l(:), l0(:)
    integer :: first, good(8), e, k, n
    character(len=24) :: line
    character(len=40) :: key

    call cube(b0, 1, .true., 0, first, good)        ! 8 nodes, 12 side triangles, tetrahedra 13..18
    l0 = text(b0)

    ! a 3D second-order type, a prism: refused naming the type and the line
    b = b0
    e = elem(b, 3, 1, 11, [1, 2, 3, 5, 4, 6, 7, 8, 1, 2])
    l = text(b)
    k = line_of(l, '3 1 11 1')
    write (line, '(a,i0)') 'line ', k
    call expect_error('p2.msh', l, '', [character(len=24) :: 'type 11', 'second order', 'gmsh -order 1', line], &
                      'a 10-node tetrahedron (type 11) is refused with its line')
    b = b0
    e = elem(b, 3, 1, 6, [1, 2, 3, 5, 6, 7])
    l = text(b)
    write (line, '(a,i0)') 'line ', line_of(l, '3 1 6 1')
    call expect_error('prism.msh', l, '', [character(len=24) :: 'prisms (type 6)', line], 'a prism is refused with its line')
    b = b0
    e = elem(b, 2, 11, 4, [1, 2, 3, 5])
    l = text(b)
    write (line, '(a,i0)') 'line ', line_of(l, '2 11 4 1')
    call expect_error('tet_on_surface.msh', l, '', [character(len=40) :: 'entity dimension 2', 'type 4', line], &
                      'a tetrahedron on a surface entity is refused with its line')

    ! a face of a group whose nodes are the body's but which is no face of its cells
    b = b0
    e = elem(b, 2, 11, 2, [2, 3, 5])
    key = 'element '//i2s(e)      ! (a typed constructor of deferred-length items overruns in gfortran 12)
    call expect_error('notface.msh', text(b), 'cube', [character(len=40) :: key, "surface 'x0'", &
                      'not a face of any cell'], 'a group face not on the body is refused naming its element')
    b = b0
    e = elem(b, 2, 11, 2, [1, 7, 5])
    key = 'elements 2 and '//i2s(e)
    call expect_error('twice.msh', text(b), 'cube', [character(len=40) :: key, 'same face'], &
                      'a face listed twice in a group is refused naming both')

    ! a missing node: the element, the node and the line
    l = l0
    k = line_of(l, '13 1 2 4 8')
    l(k) = '13 1 2 99 8'
    write (line, '(a,i0)') 'line ', k
    call expect_error('nonode.msh', l, '', [character(len=24) :: 'node 99', 'element 13', line], &
                      'a missing node is refused with its element and line')

    ! truncated: inside $Elements, and before $EndElements
    n = line_of(l0, '$Elements')
    call expect_error('trunc1.msh', l0(1:n + 5), '', [character(len=24) :: 'truncated'], &
                      'a file cut inside $Elements is refused')
    call expect_error('trunc2.msh', l0(1:size(l0) - 1), '', [character(len=24) :: 'truncated', '$EndElements'], &
                      'a file cut before $EndElements is refused')
    call expect_error('trunc3.msh', l0(1:line_of(l0, '$Nodes') + 3), '', [character(len=24) :: 'truncated'], &
                      'a file cut inside $Nodes is refused')

    ! cells: listed twice, overlapping, degenerate, twisted
    b = b0
    e = elem(b, 3, 1, 4, [4, 1, 8, 2])
    key = 'elements 13 and '//i2s(e)
    call expect_error('dup.msh', text(b), '', [character(len=40) :: key, 'same nodes'], &
                      'a tetrahedron listed twice (its nodes in another order) is refused')
    call start(b)
    e = node(b, 0.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 1.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 0.0_wp, 1.0_wp, 0.0_wp)
    e = node(b, 0.0_wp, 0.0_wp, 1.0_wp)
    e = node(b, 0.2_wp, 0.2_wp, 2.0_wp)
    e = node(b, 0.3_wp, 0.3_wp, 0.0_wp)
    call group(b, 3, 1, 'v')
    e = elem(b, 3, 1, 4, [1, 2, 3, 4])
    e = elem(b, 3, 1, 4, [1, 2, 3, 5])
    call expect_error('overlap.msh', text(b), 'v', [character(len=40) :: 'elements 1 and 2 overlap', 'same side'], &
                      'two tetrahedra on the same side of a face are refused')
    b%blk(1)%nodes(1:4, 2) = [1, 2, 3, 6]
    call expect_error('flat.msh', text(b), 'v', [character(len=40) :: 'element 2 (a tetrahedron)', 'degenerate'], &
                      'a flat tetrahedron is refused by tag')
    call start(b)
    do k = 0, 7
      e = node(b, real(merge(1, 0, any(k == [1, 2, 5, 6])), wp), real(merge(1, 0, any(k == [2, 3, 6, 7])), wp), &
               real(k/4, wp))
    end do
    call group(b, 3, 1, 'v')
    e = elem(b, 3, 1, 5, [1, 2, 3, 4, 5, 6, 8, 7])     ! the top face's last two nodes swapped
    call expect_error('twist.msh', text(b), 'v', [character(len=40) :: 'element 1 (a hexahedron)', 'one sign'], &
                      'a twisted hexahedron is refused by tag')

    ! regions: unknown, a surface, none among several; a 2D mesh in a 3D run
    call expect_error('region.msh', l0, 'nowhere', [character(len=40) :: "no physical volume 'nowhere'", "'cube'"], &
                      'an unknown region is refused, listing the volumes')
    call expect_error('region_surface.msh', l0, 'x1', [character(len=60) :: "no physical volume 'x1'", &
                      "'x1' is a physical surface"], 'a region naming a physical surface is refused, saying so')
    call start(b)
    e = node(b, 0.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 1.0_wp, 0.0_wp, 0.0_wp)
    e = node(b, 0.0_wp, 1.0_wp, 0.0_wp)
    call group(b, 2, 1, 'plate')
    e = elem(b, 2, 1, 2, [1, 2, 3])
    call expect_error('flat2d.msh', text(b), '', [character(len=60) :: 'no tetrahedra or hexahedra', 'a 2D mesh'], &
                      'a 2D mesh in a 3D run is refused')
  end subroutine test_bad_files

  ! ---- the shipped mesh ------------------------------------------------------------------------

  !> inputs/gmsh/blocks_3d.msh: 'lower' hexahedra on (0,1)^3, 'upper' tetrahedra on
  !! (0,1)x(1,2)x(0,1); each body's volume 1, its six face groups outward of area 1.
  subroutine test_shipped()
    character(len=*), parameter :: path = 'inputs/gmsh/blocks_3d.msh'
    character(len=6), parameter :: sides(6) = ['x0    ', 'x1    ', 'bottom', 'top   ', 'z0    ', 'z1    ']
    real(wp), parameter :: normals(3, 6) = reshape([-1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1], [3, 6])
    type(mesh_t) :: m
    integer :: body, s, c, nf, nneg, ngood
    real(wp) :: total, jmin, vol, dev, area, worst
    logical :: on_cell
    character(len=5) :: name
    do body = 1, 2
      name = trim(merge('lower', 'upper', body == 1))
      call read_ok(path, trim(name), m, path//' '//trim(name))
      if (m%ncell == 0) cycle
      total = 0.0_wp
      nneg = 0
      do c = 1, m%ncell
        call cell_measure(m, c, jmin, vol)
        if (.not. jmin > 0.0_wp) nneg = nneg + 1
        total = total + vol
      end do
      call report(nneg == 0 .and. m%element == merge(ELEM_HEX8, ELEM_TET4, body == 1), &
                  path//' '//trim(name)//': '//trim(merge('hexahedra ', 'tetrahedra', body == 1))//', '// &
                  i2s(m%ncell)//' cells, all positive')
      call report_le(abs(total - 1.0_wp), 1.0e-13_wp, path//' '//trim(name)//': volume 1')
      worst = 0.0_wp
      ngood = 0
      do s = 1, 6
        call group_faces(m, trim(name)//'_'//trim(sides(s)), real(normals(:, s), wp), dev, area, nf, on_cell)
        worst = max(worst, dev, abs(area - 1.0_wp))
        if (nf > 0 .and. on_cell) ngood = ngood + 1
      end do
      call report(ngood == 6 .and. worst < 1.0e-13_wp, path//' '//trim(name)//': six face groups, outward, '// &
                  'area 1 each')
    end do
  end subroutine test_shipped

  subroutine delete(path)
    character(len=*), intent(in) :: path
    integer :: u
    open (newunit=u, file=path)
    close (u, status='delete')
  end subroutine delete

  ! ---- benchmark ----------------------------------------------------------------------------

  subroutine bench(path)
    character(len=*), intent(in) :: path
    type(mesh_t) :: m
    type(error_t) :: err
    integer(8) :: t0, t1, rate
    character(len=512) :: region
    region = ''
    if (command_argument_count() >= 2) call get_command_argument(2, region)
    call system_clock(t0, rate)
    call msh_read(path, trim(region), 1, m, err)
    call system_clock(t1)
    if (err%failed()) then
      write (*, '(a)') err%text()
      error stop 1
    end if
    write (*, '(a,i0,a,i0,a,i0,a,i0,a,f8.3,a)') 'read ', m%nnode, ' nodes (', 3*m%nnode, ' DOFs), ', &
      m%ncell, ' cells, ', m%ngroup, ' groups in ', real(t1 - t0, wp)/real(rate, wp), ' s'
  end subroutine bench

end program test_gmsh_3d
