!> Unit tests of module gmsh_msh: the shipped meshes of inputs/gmsh (counts, areas, grid
!! coordinates, boundary groups and their outward normals, refinement), and small bad or
!! unusual MSH files written here (binary, version 2.2, missing node, 3D, second order,
!! unknown region, clockwise cells, degenerate and non-convex cells, sparse unordered tags,
!! truncation, unknown sections, numbers in every form, cells and boundary lines listed
!! twice, tags < 1, counts the file cannot hold), and groups of nodes (physical
!! points, a physical curve inside a body). The stiffness and lifting of bodies read from
!! files are those of an element loop in file order, bit for bit. Bodies read together from
!! one file of many (each a small part of it) equal the bodies read one by one.
!!
!! With arguments, `test_gmsh file.msh [region]` only reads that file and prints the time
!! taken (the read benchmark).
program test_gmsh
  use kinds, only: wp
  use config, only: ELEM_Q1, ELEM_P1, ELEM_MIXED
  use mesh, only: mesh_t, group_index, group_nodes, group_names, nodes_only, nodes_only_refusal, file_order, file_cells
  use gmsh_msh, only: msh_read_err => msh_read, msh_read_shared
  use digest, only: file_digest
  use errors, only: error_t, exit_code
  use strings, only: i2s, word
  use testing, only: report, report_le, test_summary, write_file
  use config, only: body_cfg_t, boundary_cfg_t, traction_cfg_t
  use elements, only: MAX_NVERT, MAX_NDOF, ke_cache_t, ke_cache_init, element_stiffness
  use assembly, only: assemble_body, body_system_t, lame_parameters
  implicit none (type, external)

  real(wp), parameter :: pi = acos(-1.0_wp), eps = epsilon(1.0_wp)
  character(len=*), parameter :: dir = 'inputs/gmsh/'
  character(len=:), allocatable :: tmp
  character(len=256) :: arg

  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    call bench(trim(arg))
    stop
  end if
  call get_environment_variable('BUILD', arg)
  if (len_trim(arg) == 0) arg = 'build/release'
  tmp = trim(arg)//'/test_gmsh_'

  call test_paper()
  call test_nonmatching()
  call test_patch()
  call test_hertz()
  call test_hertz_force()
  call test_bad_inputs()
  call test_point_groups()
  call test_unusual_inputs()
  call test_file_order(dir//'hertz_h0.02.msh', 'disc', 'disc_top')
  call test_file_order(dir//'hertz_h0.02.msh', 'block', 'block_bottom')
  call test_file_order(dir//'paper.msh', 'upper', 'upper_left')
  call test_file_order(dir//'patch_mixed.msh', 'top', 'top_top')
  call test_file_order(dir//'pin_hole.msh', 'plate', 'plate_left')
  call test_locality(dir//'hertz_h0.02.msh', 'disc')
  call test_locality(dir//'pin_hole.msh', 'plate')
  call test_shared('tests/data/blocks18.msh', 18)
  call test_summary()

contains

  ! ---- helpers --------------------------------------------------------------------------

  !> The node tags in the file's order (mesh%file_node).
  function file_tags(m) result(tags)
    type(mesh_t), intent(in) :: m
    integer, allocatable :: tags(:)
    allocate (tags(m%nnode))
    tags(m%file_node) = m%node_tag
  end function file_tags

  !> msh_read with its error as an exit code (0; 1 bad input; 3 other) and a message.
  subroutine msh_read(path, region, body_id, m, info, msg)
    character(len=*), intent(in) :: path, region
    integer, intent(in) :: body_id
    type(mesh_t), intent(out) :: m
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(error_t) :: err
    call msh_read_err(path, region, body_id, m, err)
    info = exit_code(err)
    msg = err%text()
  end subroutine msh_read

  subroutine read_ok(path, region, m)
    character(len=*), intent(in) :: path, region
    type(mesh_t), intent(out) :: m
    integer :: info
    character(len=512) :: msg
    call msh_read(path, region, 1, m, info, msg)
    call report(info == 0, 'read '//path//" region '"//region//"'"//merge('          ', ': '//msg(1:8), info == 0))
    if (info /= 0) then
      write (*, '(a)') trim(msg)
      call test_summary()
      error stop 1
    end if
  end subroutine read_ok

  !> Twice the signed area of cell c.
  pure real(wp) function area2(m, c)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: c
    integer :: nv, i, a, b
    nv = merge(4, 3, m%cell_type(c) == ELEM_Q1)
    area2 = 0.0_wp
    do i = 1, nv
      a = m%cells(i, c)
      b = m%cells(modulo(i, nv) + 1, c)
      area2 = area2 + m%xy(1, a)*m%xy(2, b) - m%xy(1, b)*m%xy(2, a)
    end do
  end function area2

  real(wp) function total_area(m)
    type(mesh_t), intent(in) :: m
    integer :: c
    total_area = 0.0_wp
    do c = 1, m%ncell
      total_area = total_area + 0.5_wp*area2(m, c)
    end do
  end function total_area

  logical function all_ccw(m)
    type(mesh_t), intent(in) :: m
    integer :: c
    all_ccw = .true.
    do c = 1, m%ncell
      all_ccw = all_ccw .and. area2(m, c) > 0.0_wp
    end do
  end function all_ccw

  !> Group g's edges: the largest deviation of their unit outward normal from `normal`,
  !! and the sum of their lengths.
  subroutine group_normal(m, name, normal, dev, length, nedge)
    type(mesh_t), intent(in) :: m
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: normal(2)
    real(wp), intent(out) :: dev, length
    integer, intent(out) :: nedge
    integer :: g, k
    real(wp) :: d(2), l
    dev = huge(1.0_wp)
    length = 0.0_wp
    nedge = 0
    g = group_index(m, name)
    if (g == 0) return
    dev = 0.0_wp
    nedge = m%group(g)%nedge
    do k = 1, nedge
      d = m%xy(:, m%group(g)%edge(2, k)) - m%xy(:, m%group(g)%edge(1, k))
      l = norm2(d)
      length = length + l
      dev = max(dev, norm2([d(2), -d(1)]/l - normal))
    end do
  end subroutine group_normal

  !> Every group edge is two consecutive vertices of its cell, in the cell's order.
  logical function groups_follow_cells(m)
    type(mesh_t), intent(in) :: m
    integer :: g, k, c, i, nv
    logical :: found
    groups_follow_cells = .true.
    do g = 1, m%ngroup
      do k = 1, m%group(g)%nedge
        c = m%group(g)%cell(k)
        nv = merge(4, 3, m%cell_type(c) == ELEM_Q1)
        found = .false.
        do i = 1, nv
          found = found .or. (m%cells(i, c) == m%group(g)%edge(1, k) .and. &
                              m%cells(modulo(i, nv) + 1, c) == m%group(g)%edge(2, k))
        end do
        groups_follow_cells = groups_follow_cells .and. found
      end do
    end do
  end function groups_follow_cells

  !> The x coordinates of a group's nodes.
  function group_x(m, name) result(x)
    type(mesh_t), intent(in) :: m
    character(len=*), intent(in) :: name
    real(wp), allocatable :: x(:)
    integer :: g
    g = group_index(m, name)
    allocate (x(0))
    if (g > 0) x = [m%xy(1, m%group(g)%edge(1, :)), m%xy(1, m%group(g)%edge(2, :))]
  end function group_x

  !> Write `lines` to a temporary file, read it, and check info and that msg holds every
  !! key word (the file name is always one).
  subroutine expect_error(name, lines, region, want_info, keys, what)
    character(len=*), intent(in) :: name, lines(:), region
    integer, intent(in) :: want_info
    character(len=*), intent(in) :: keys(:), what
    type(mesh_t) :: m
    integer :: info, k, u
    character(len=1024) :: msg
    logical :: has
    call write_file(tmp//name, lines)
    call msh_read(tmp//name, region, 2, m, info, msg)
    has = index(msg, tmp//name) > 0 .and. index(msg, 'body 2') > 0
    do k = 1, size(keys)
      has = has .and. index(msg, trim(keys(k))) > 0
    end do
    call report(info == want_info .and. has, what)
    write (*, '(a)') '      msg: '//trim(msg)
    open (newunit=u, file=tmp//name)
    close (u, status='delete')
  end subroutine expect_error

  ! ---- assembly order ---------------------------------------------------------------------

  !> assemble_body on a body read from a file gives the stiffness and the lifting of the
  !! element loop in file order (each entry the sum of its cells' terms in cell order,
  !! with the one-cell stiffness cache), bit for bit: the reference is summed here into
  !! the same pattern. `group` is held at a non-zero displacement (a lifting).
  subroutine test_file_order(path, region, group)
    character(len=*), intent(in) :: path, region, group
    type(mesh_t) :: m
    type(body_cfg_t) :: body
    type(boundary_cfg_t) :: bnd(1)
    type(traction_cfg_t) :: tr(1)
    type(body_system_t) :: sys
    type(error_t) :: err
    type(ke_cache_t) :: cache
    real(wp), allocatable :: val(:), f(:)
    real(wp) :: ke(MAX_NDOF, MAX_NDOF), xe(2, MAX_NVERT), minjac, lame_lambda, lame_mu, ue(MAX_NDOF)
    integer :: c, nv, a, b, fa, fb, pos, ldof(MAX_NDOF)
    character(len=:), allocatable :: what

    what = path//' '//region//': '
    call msh_read_err(path, region, 1, m, err)
    body%id = 1
    body%young = 2.1e11_wp
    body%poisson = 0.277_wp
    bnd(1)%body = 1
    bnd(1)%group = group
    bnd(1)%fix = .true.
    bnd(1)%u(1:2) = [1.0e-3_wp, -2.0e-3_wp]
    if (.not. err%failed()) call assemble_body(m, body, .true., tr, 0, sys, err, boundaries=bnd)
    if (err%failed()) then
      call report(.false., what//'read and assembled: '//err%text())
      return
    end if
    call lame_parameters(body, .true., lame_lambda, lame_mu)
    call ke_cache_init(cache, maxval(abs(m%xy)))
    allocate (val(size(sys%val)), f(sys%n))
    val = 0.0_wp
    f = 0.0_wp
    do c = 1, m%ncell
      nv = merge(4, 3, m%cell_type(c) == ELEM_Q1)
      xe = 0.0_wp
      do a = 1, nv
        xe(:, a) = m%xy(:, m%cells(a, c))
        ldof(2*a - 1:2*a) = 2*m%cells(a, c) - [1, 0]
      end do
      call element_stiffness(m%cell_type(c), xe, lame_lambda, lame_mu, ke, minjac, cache)
      ue(1:2*nv) = sys%u_fixed(ldof(1:2*nv))
      do b = 1, 2*nv
        fb = sys%free_of(ldof(b))
        if (fb == 0) cycle
        do a = 1, 2*nv
          fa = sys%free_of(ldof(a))
          if (fa == 0) cycle
          pos = sys%colptr(fb) + findloc(sys%rowind(sys%colptr(fb) + 1:sys%colptr(fb + 1)), fa - 1, dim=1)
          val(pos) = val(pos) + ke(a, b)
        end do
        if (any(ue(1:2*nv) /= 0.0_wp)) f(fb) = f(fb) - dot_product(ke(b, 1:2*nv), ue(1:2*nv))
      end do
    end do
    call report(all(sys%val == val), what//'stiffness = the file-order sums, bit for bit')
    call report(any(f /= 0.0_wp) .and. all(sys%f == f), what//'lifting = the file-order sums, bit for bit')
  end subroutine test_file_order

  ! ---- numbering for locality -----------------------------------------------------------

  !> The n bodies 'b1'..'bn' of one file read together (msh_read_shared: the file parsed
  !! once, each body found from the file's indexes, a small part of the file) equal each
  !! read alone (msh_read: the passes over the whole file): nodes, coordinates, cells,
  !! tags, file order, groups (edges, their cells, single nodes) and the group names; the
  !! content hash computed beside the parse (and by msh_read) is the file's (file_digest).
  subroutine test_shared(path, n)
    character(len=*), intent(in) :: path
    integer, intent(in) :: n
    type(mesh_t), allocatable :: m(:)
    type(mesh_t) :: one
    type(error_t), allocatable :: errs(:)
    type(error_t) :: err
    character(len=16) :: region(n), hex, hex_file
    integer :: a, g, nbad, nedge
    logical :: same
    do a = 1, n
      region(a) = 'b'//i2s(a)
    end do
    allocate (m(n), errs(n))
    call msh_read_shared(path, region, [(a, a=1, n)], m, errs, 2, hex)
    call file_digest(path, hex_file, err)
    call report(.not. err%failed() .and. hex == hex_file, path//': the content hash of the bytes read together ('// &
                hex//') = the file'//"'"//'s, read again ('//hex_file//')')
    call msh_read_err(path, 'b1', 1, one, err, hex)
    call report(hex == hex_file, path//': the content hash of a body read alone = the file'//"'"//'s ('//hex//')')
    nbad = 0
    nedge = 0
    do a = 1, n
      call msh_read_err(path, trim(region(a)), a, one, err)
      same = .not. errs(a)%failed() .and. .not. err%failed()
      if (same) same = m(a)%nnode == one%nnode .and. m(a)%ncell == one%ncell .and. m(a)%element == one%element
      if (same) same = all(m(a)%xy == one%xy) .and. all(m(a)%cells == one%cells) .and. &
                       all(m(a)%node_tag == one%node_tag) .and. all(m(a)%cell_tag == one%cell_tag) .and. &
                       all(m(a)%file_node == one%file_node) .and. all(m(a)%file_cell == one%file_cell) .and. &
                       m(a)%ngroup == one%ngroup .and. m(a)%file_groups == one%file_groups
      if (same) then
        do g = 1, one%ngroup
          same = same .and. m(a)%group(g)%name == one%group(g)%name .and. &
                 m(a)%group(g)%nedge == one%group(g)%nedge .and. m(a)%group(g)%nnode == one%group(g)%nnode
          if (.not. same) exit
          same = all(m(a)%group(g)%edge == one%group(g)%edge) .and. all(m(a)%group(g)%cell == one%group(g)%cell) .and. &
                 all(m(a)%group(g)%node == one%group(g)%node)
          nedge = nedge + one%group(g)%nedge
        end do
      end if
      if (.not. same) nbad = nbad + 1
    end do
    call report(nbad == 0 .and. nedge >= 4*n, path//': '//i2s(n)//' bodies read together = read one by one '// &
                '(mismatches '//i2s(nbad)//', '//i2s(nedge)//' group edges)')
  end subroutine test_shared

  !> A body read from a file is numbered for locality: file_node and file_cell are
  !! permutations, file_cells gives back the file's cells (the node tags of each cell as the
  !! file lists them, up to orientation), and the cells' node numbers spread far less than
  !! in the file's order (the mean over cells of the largest minus the smallest node number,
  !! and of the jump of the smallest node number from one cell to the next).
  subroutine test_locality(path, region)
    character(len=*), intent(in) :: path, region
    type(mesh_t) :: m
    type(error_t) :: err
    integer, allocatable :: tags(:), fc(:, :), seen(:)
    integer :: c, nv
    real(wp) :: spread_new, spread_file, jump_new, jump_file
    logical :: same
    character(len=:), allocatable :: what

    what = path//' '//region//': '
    call msh_read_err(path, region, 1, m, err)
    if (err%failed()) then
      call report(.false., what//'read: '//err%text())
      return
    end if
    allocate (seen(max(m%nnode, m%ncell)))
    seen = 0
    seen(m%file_node) = 1
    call report(size(m%file_node) == m%nnode .and. all(seen(1:m%nnode) == 1), what//'file_node is a permutation')
    seen = 0
    seen(m%file_cell) = 1
    call report(size(m%file_cell) == m%ncell .and. all(seen(1:m%ncell) == 1), what//'file_cell is a permutation')
    tags = file_tags(m)
    fc = file_cells(m)
    same = .true.
    do c = 1, m%ncell
      nv = merge(4, 3, m%cell_type(c) == ELEM_Q1)
      same = same .and. all(tags(fc(1:nv, m%file_cell(c))) == m%node_tag(m%cells(1:nv, c)))
    end do
    call report(same, what//'file_cells: each cell with its nodes in the file''s numbering')
    call spreads(m%cells, spread_new, jump_new)
    call spreads(fc, spread_file, jump_file)
    call report(spread_new < 0.25_wp*spread_file .and. jump_new < 0.25_wp*jump_file, what// &
                'numbered for locality: node spread per cell '//i2s(nint(spread_new))//' (file '//i2s(nint(spread_file))// &
                '), jump between cells '//i2s(nint(jump_new))//' (file '//i2s(nint(jump_file))//')')
  end subroutine test_locality

  !> The mean over cells of the largest minus the smallest node number, and the mean jump
  !! of the smallest node number from one cell to the next.
  subroutine spreads(cells, spread, jump)
    integer, intent(in) :: cells(:, :)
    real(wp), intent(out) :: spread, jump
    integer :: k, lo, prev
    spread = 0.0_wp
    jump = 0.0_wp
    prev = 0
    do k = 1, size(cells, 2)
      lo = minval(cells(:, k), mask=cells(:, k) > 0)
      spread = spread + (maxval(cells(:, k)) - lo)
      if (k > 1) jump = jump + abs(lo - prev)
      prev = lo
    end do
    spread = spread/size(cells, 2)
    jump = jump/max(1, size(cells, 2) - 1)
  end subroutine spreads

  ! ---- the shipped meshes ---------------------------------------------------------------

  subroutine test_paper()
    type(mesh_t) :: up, lo
    integer, allocatable :: tags(:)
    real(wp) :: dev, length, offgrid
    integer :: ne, k, info
    character(len=512) :: msg

    call read_ok(dir//'paper.msh', 'upper', up)
    call report(up%nnode == 25*17 .and. up%ncell == 24*16, 'paper upper: 25*17 nodes, 24*16 cells')
    call report(up%element == ELEM_Q1 .and. up%nvert == 4 .and. all(up%cell_type == ELEM_Q1), &
                'paper upper: all Q1')
    call report_le(abs(total_area(up) - 3.0_wp), 100*eps*3, 'paper upper: area 3')
    call report(all_ccw(up), 'paper upper: cells counter-clockwise')
    offgrid = 0.0_wp
    do k = 1, up%nnode
      offgrid = max(offgrid, abs(up%xy(1, k)*8 - nint(up%xy(1, k)*8)), &
                    abs((up%xy(2, k) - 1)*16 - nint((up%xy(2, k) - 1)*16)))
    end do
    call report_le(offgrid, 8*eps, 'paper upper: nodes on the uniform 24x16 grid')
    call report(up%x0 == 0.0_wp .and. up%y0 == 1.0_wp .and. abs(up%width - 3) < 1e-14_wp .and. &
                abs(up%height - 1) < 1e-14_wp, 'paper upper: bounding box (0,3)x(1,2)')
    tags = file_tags(up)
    call report(all(tags(2:) > tags(:up%nnode - 1)), 'paper upper: the file order is by increasing tag')
    call report(.not. up%structured .and. up%source == dir//'paper.msh' .and. up%nx == 0, &
                'paper upper: unstructured, source is the file')
    call group_normal(up, 'upper_bottom', [0.0_wp, -1.0_wp], dev, length, ne)
    call report(ne == 24, 'paper upper_bottom: 24 edges')
    call report_le(dev, 1.0e-12_wp, 'paper upper_bottom: outward normal (0,-1)')
    call report_le(abs(length - 3), 1.0e-12_wp, 'paper upper_bottom: length 3')
    call group_normal(up, 'upper_left', [-1.0_wp, 0.0_wp], dev, length, ne)
    call report(ne == 16 .and. dev < 1e-12_wp .and. abs(length - 1) < 1e-12_wp, &
                'paper upper_left: 16 edges, normal (-1,0), length 1')
    call group_normal(up, 'upper_right', [1.0_wp, 0.0_wp], dev, length, ne)
    call report(ne == 16 .and. dev < 1e-12_wp, 'paper upper_right: 16 edges, normal (1,0)')
    call group_normal(up, 'upper_top', [0.0_wp, 1.0_wp], dev, length, ne)
    call report(ne == 24 .and. dev < 1e-12_wp, 'paper upper_top: 24 edges, normal (0,1)')
    call report(up%ngroup == 4 .and. group_index(up, 'lower_top') == 0, &
                'paper upper: only its 4 groups (none of the lower body)')
    call report(index(up%file_groups, 'lower_top') > 0 .and. index(up%file_groups, 'upper_left') > 0, &
                'paper upper: file_groups lists every physical curve')
    call report(groups_follow_cells(up), 'paper upper: group edges follow their cells')

    call read_ok(dir//'paper.msh', 'lower', lo)
    call report(lo%nnode == 25*17 .and. lo%ncell == 24*16 .and. lo%y0 == 0.0_wp, &
                'paper lower: 25*17 nodes, 24*16 cells, from y = 0')
    call report(minval(lo%node_tag) > maxval(up%node_tag) .or. maxval(lo%node_tag) < minval(up%node_tag) &
                .or. .not. any([(any(lo%node_tag == up%node_tag(k)), k=1, up%nnode)]), &
                'paper: the bodies have distinct nodes')
    call group_normal(lo, 'lower_top', [0.0_wp, 1.0_wp], dev, length, ne)
    call report(ne == 24 .and. dev < 1e-12_wp .and. abs(length - 3) < 1e-12_wp, &
                'paper lower_top: 24 edges, normal (0,1), length 3')
    call group_normal(lo, 'lower_left', [-1.0_wp, 0.0_wp], dev, length, ne)
    call report(ne == 16 .and. dev < 1e-12_wp .and. abs(length - 1) < 1e-12_wp, &
                'paper lower_left: 16 edges, normal (-1,0), length 1')
    call group_normal(lo, 'lower_right', [1.0_wp, 0.0_wp], dev, length, ne)
    call report(ne == 16 .and. dev < 1e-12_wp, 'paper lower_right: 16 edges, normal (1,0)')
    call group_normal(lo, 'lower_bottom', [0.0_wp, -1.0_wp], dev, length, ne)
    call report(ne == 24 .and. dev < 1e-12_wp, 'paper lower_bottom: 24 edges, normal (0,-1)')

    call msh_read(dir//'paper.msh', '', 1, lo, info, msg)
    call report(info == 1 .and. index(msg, "'upper'") > 0 .and. index(msg, "'lower'") > 0, &
                'paper: no region with two physical surfaces is refused, naming them')
    write (*, '(a)') '      msg: '//trim(msg)
    call msh_read(dir//'paper.msh', 'middle', 1, lo, info, msg)
    call report(info == 1 .and. index(msg, "'middle'") > 0 .and. index(msg, "'upper', 'lower'") > 0 &
                .and. index(msg, 'paper.msh') > 0, 'paper: an unknown region is refused, listing the surfaces')
    write (*, '(a)') '      msg: '//trim(msg)
  end subroutine test_paper

  subroutine test_nonmatching()
    type(mesh_t) :: up, lo
    integer :: k
    integer, parameter :: nu(3) = [12, 24, 48], nl(3) = [18, 36, 72]
    character(len=64) :: name
    do k = 1, 3
      write (name, '(a,i0,a,i0,a)') 'paper_nonmatching_', nu(k), '_', nl(k), '.msh'
      call read_ok(dir//trim(name), 'upper', up)
      call read_ok(dir//trim(name), 'lower', lo)
      call report(up%ncell == nu(k)*(2*nu(k)/3) .and. up%nnode == (nu(k) + 1)*(2*nu(k)/3 + 1) .and. &
                  lo%ncell == nl(k)*(2*nl(k)/3) .and. lo%nnode == (nl(k) + 1)*(2*nl(k)/3 + 1) .and. &
                  up%element == ELEM_Q1 .and. lo%element == ELEM_Q1, trim(name)//': cell and node counts')
      call report(abs(total_area(up) - 3) < 1e-12_wp .and. abs(total_area(lo) - 3) < 1e-12_wp, &
                  trim(name)//': areas 3 and 3')
      call report(size(group_x(up, 'upper_bottom')) == 2*nu(k) .and. &
                  size(group_x(lo, 'lower_top')) == 2*nl(k), trim(name)//': contact edges nu and nl')
    end do
  end subroutine test_nonmatching

  subroutine test_patch()
    type(mesh_t) :: top, bot
    real(wp) :: dev, length
    real(wp), allocatable :: xt(:), xb(:)
    integer :: ne, i, ncommon

    allocate (xt(0), xb(0))
    call read_ok(dir//'patch.msh', 'top', top)
    call read_ok(dir//'patch.msh', 'bottom', bot)
    call report(top%element == ELEM_P1 .and. top%nvert == 3 .and. all(top%cell_type == ELEM_P1), &
                'patch top: triangles')
    call report(bot%element == ELEM_Q1 .and. bot%ncell == 25, 'patch bottom: 5x5 quadrangles')
    call report_le(abs(total_area(top) - 0.5_wp), 100*eps, 'patch top: triangle areas sum to 0.5')
    call report_le(abs(total_area(bot) - 1.0_wp), 100*eps, 'patch bottom: quadrangle areas sum to 1')
    call report(all_ccw(top) .and. all_ccw(bot), 'patch: cells counter-clockwise')
    call group_normal(top, 'top_bottom', [0.0_wp, -1.0_wp], dev, length, ne)
    call report(ne == 7 .and. dev < 1e-12_wp .and. abs(length - 1) < 1e-12_wp, &
                'patch top_bottom: 7 edges, normal (0,-1), length 1')
    call group_normal(bot, 'bottom_top', [0.0_wp, 1.0_wp], dev, length, ne)
    call report(ne == 5 .and. dev < 1e-12_wp .and. abs(length - 1) < 1e-12_wp, &
                'patch bottom_top: 5 edges, normal (0,1), length 1')
    xt = group_x(top, 'top_bottom')
    xb = group_x(bot, 'bottom_top')
    ncommon = 0
    do i = 1, size(xt)
      if (any(abs(xb - xt(i)) < 1e-9_wp)) ncommon = ncommon + 1
    end do
    ! only the ends x = 0 and x = 1 coincide (each listed once per edge it ends)
    call report(ncommon == 2 .and. size(xt) == 14, 'patch: contact nodes do not match (only the two ends)')
    call report(groups_follow_cells(top) .and. groups_follow_cells(bot), 'patch: group edges follow their cells')
  end subroutine test_patch

  subroutine test_hertz()
    type(mesh_t) :: disc, block
    character(len=*), parameter :: hs(3) = ['0.04', '0.02', '0.01']
    real(wp) :: h, a, seg, rdev, c(2), d(2), mid(2), boundary, lmin, dev, length
    integer :: k, g, e, ne
    character(len=:), allocatable :: name
    logical :: outward
    character(len=8) :: hbuf

    c = [0.0_wp, 2.0_wp]
    do k = 1, 3
      name = 'hertz_h'//hs(k)//'.msh'
      hbuf = hs(k)
      read (hbuf, *) h
      call read_ok(dir//name, 'disc', disc)
      call read_ok(dir//name, 'block', block)
      call report(disc%element == ELEM_P1 .and. block%element == ELEM_P1 .and. all_ccw(disc) .and. &
                  all_ccw(block), name//': triangles, counter-clockwise')
      ! the disc: the cells' area is the polygon's (shoelace over its boundary groups), and
      ! short of pi/2 by the circular segments cut off by the arc's chords
      a = total_area(disc)
      boundary = 0.0_wp
      seg = 0.0_wp
      rdev = 0.0_wp
      outward = .true.
      lmin = huge(1.0_wp)
      do g = 1, disc%ngroup
        do e = 1, disc%group(g)%nedge
          associate (p => disc%xy(:, disc%group(g)%edge(1, e)), q => disc%xy(:, disc%group(g)%edge(2, e)))
            boundary = boundary + 0.5_wp*(p(1)*q(2) - q(1)*p(2))
            if (disc%group(g)%name == 'disc_arc') then
              d = q - p
              seg = seg + norm2(d)**3/12.0_wp          ! segment area ~ chord^3 / (12 R)
              rdev = max(rdev, abs(norm2(p - c) - 1), abs(norm2(q - c) - 1))
              mid = 0.5_wp*(p + q)
              outward = outward .and. dot_product([d(2), -d(1)], mid - c) > 0.0_wp
              lmin = min(lmin, norm2(d))
            end if
          end associate
        end do
      end do
      call report(disc%ngroup == 2 .and. group_index(disc, 'disc_top') > 0 .and. &
                  group_index(disc, 'disc_arc') > 0, name//': disc groups disc_top, disc_arc')
      call report_le(abs(a - boundary), 1e-12_wp, name//': disc cells fill its boundary polygon')
      call report(pi/2 - a > 0.0_wp .and. abs(pi/2 - a - seg) <= 0.02_wp*seg, &
                  name//': disc area pi/2 less the chord segments', pi/2 - a, seg)
      call report_le(rdev, 1e-12_wp, name//': disc_arc nodes on the circle')
      call report(outward, name//': disc_arc outward normals point away from the centre')
      call report(lmin <= 1.2_wp*h .and. lmin >= 0.5_wp*h, name//': arc edges of size h at the contact', lmin, h)
      call group_normal(disc, 'disc_top', [0.0_wp, 1.0_wp], dev, length, ne)
      call report(dev < 1e-12_wp .and. abs(length - 2) < 1e-12_wp, name//': disc_top normal (0,1), length 2')
      call group_normal(block, 'block_top', [0.0_wp, 1.0_wp], dev, length, ne)
      call report(dev < 1e-12_wp .and. abs(length - 8) < 1e-12_wp, name//': block_top normal (0,1), length 8')
      call report(block%ngroup == 4 .and. abs(total_area(block) - 32) < 1e-12_wp*32 .and. &
                  block%x0 == -4 .and. block%y0 == -3, name//': block (-4,4)x(-3,1), 4 groups')
      call report(any(disc%xy(1, :) == 0 .and. disc%xy(2, :) == 1) .and. &
                  any(block%xy(1, :) == 0 .and. block%xy(2, :) == 1), name//': both bodies have a node at (0,1)')
    end do
  end subroutine test_hertz

  !> The force-controlled Hertz geometry: the disc in two quarters, its axis a curve inside
  !! it, its centre a physical point sharing the disc mesh's node.
  subroutine test_hertz_force()
    type(mesh_t) :: disc, block
    character(len=*), parameter :: hs(2) = ['0.04', '0.02']
    integer, allocatable :: nodes(:)
    integer :: k, g, ne
    real(wp) :: h, dev, length
    character(len=:), allocatable :: name
    character(len=8) :: hbuf

    do k = 1, 2
      name = 'hertz_force_h'//hs(k)//'.msh'
      hbuf = hs(k)
      read (hbuf, *) h
      call read_ok(dir//name, 'disc', disc)
      call read_ok(dir//name, 'block', block)
      call report(disc%element == ELEM_P1 .and. all_ccw(disc) .and. all_ccw(block), &
                  name//': triangles, counter-clockwise')
      call group_normal(disc, 'disc_top', [0.0_wp, 1.0_wp], dev, length, ne)
      call report(dev < 1e-12_wp .and. abs(length - 2) < 1e-12_wp, name//': disc_top (both halves) normal (0,1), length 2')
      g = group_index(disc, 'disc_centre')
      call report(g > 0, name//': the disc has the point group disc_centre')
      if (g > 0) then
        call group_nodes(disc, g, nodes)
        call report(nodes_only(disc, g) .and. disc%group(g)%point .and. size(nodes) == 1, &
                    name//': disc_centre is one node, no edge')
        if (size(nodes) == 1) call report(all(disc%xy(:, nodes(1)) == [0.0_wp, 2.0_wp]) .and. &
                                          any(disc%cells == nodes(1)), name//': disc_centre is the disc''s node at (0,2)')
      end if
      g = group_index(disc, 'disc_axis')
      call report(g > 0, name//': the disc has the group disc_axis')
      if (g > 0) then
        call group_nodes(disc, g, nodes)
        call report(nodes_only(disc, g) .and. .not. disc%group(g)%point .and. size(nodes) == count(disc%xy(1, :) == 0) .and. &
                    all(disc%xy(1, nodes) == 0) .and. minval(disc%xy(2, nodes)) == 1 .and. &
                    maxval(disc%xy(2, nodes)) == 2, name//': disc_axis: every node of x = 0, 1 <= y <= 2, no edge')
      end if
      call report(group_index(block, 'disc_centre') == 0 .and. group_index(block, 'disc_axis') == 0 .and. &
                  block%ngroup == 4, name//': the block has neither disc_centre nor disc_axis')
      call report(index(block%file_groups, 'physical points: disc_centre') > 0, &
                  name//': file_groups lists the physical point')
    end do
  end subroutine test_hertz_force

  !> Groups of nodes in a small file of two bodies: body 'a' (two triangles, their shared
  !! diagonal on the curve 'diag'), body 'b' (a quadrangle). The physical point 'corner' is
  !! a node of a; 'free_pt' is a node in no cell, at the place of a node of b; 'both' holds
  !! both points; the point 'base' is named as the curve 'base' (its node joins the curve's).
  subroutine test_point_groups()
    type(mesh_t) :: a, b
    integer, allocatable :: nodes(:)
    integer :: info, g, u
    character(len=512) :: msg
    character(len=:), allocatable :: s

    call write_file(tmp//'points.msh', [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', &
      '$PhysicalNames', '8', '0 1 "corner"', '0 2 "free_pt"', '0 3 "both"', '0 4 "base"', &
      '1 10 "base"', '1 11 "diag"', '2 20 "a"', '2 21 "b"', '$EndPhysicalNames', &
      '$Entities', '3 2 2 0', '1 1 1 0 2 1 3', '2 0 3 0 2 2 3', '3 0 0 0 1 4', &
      '1 0 0 0 1 0 0 1 10 0', '2 0 0 0 1 1 0 1 11 0', '1 0 0 0 1 1 0 1 20 0', '2 0 2 0 1 3 0 1 21 0', &
      '$EndEntities', &
      '$Nodes', '1 9 1 9', '2 1 0 9', '1', '2', '3', '4', '5', '6', '7', '8', '9', &
      '0 0 0', '1 0 0', '1 1 0', '0 1 0', '0 2 0', '1 2 0', '1 3 0', '0 3 0', '0 3 0', '$EndNodes', &
      '$Elements', '7 8 101 401', '0 1 15 1', '101 3', '0 2 15 1', '102 9', '0 3 15 1', '103 1', &
      '1 1 1 1', '201 1 2', '1 2 1 1', '202 1 3', '2 1 2 2', '301 1 2 3', '302 1 3 4', &
      '2 2 3 1', '401 5 6 7 8', '$EndElements'])
    call msh_read(tmp//'points.msh', 'a', 1, a, info, msg)
    call report(info == 0, 'physical points: body a is read')
    if (info /= 0) write (*, '(a)') trim(msg)
    call msh_read(tmp//'points.msh', 'b', 2, b, info, msg)
    call report(info == 0, 'physical points: body b is read')
    if (info /= 0) write (*, '(a)') trim(msg)
    open (newunit=u, file=tmp//'points.msh')
    close (u, status='delete')
    if (a%nnode /= 4 .or. b%nnode /= 4) return

    g = group_index(a, 'corner')
    call report(g > 0, "body a has the point group 'corner'")
    if (g > 0) then
      call group_nodes(a, g, nodes)
      call report(nodes_only(a, g) .and. a%group(g)%point .and. a%group(g)%nedge == 0 .and. size(nodes) == 1, &
                  "'corner': one node, no edge")
      if (size(nodes) == 1) call report(a%node_tag(nodes(1)) == 3, "'corner' is the node of tag 3 (shared with the cells)")
      call nodes_only_refusal(a, g, 'a traction needs', s)
      call report(index(s, "group 'corner' is a physical point: a traction needs a curve") > 0, &
                  'a point group is refused for a traction: '//s)
    end if
    call report(group_index(a, 'free_pt') == 0, "body a has no 'free_pt' (its node is at b's place)")
    g = group_index(a, 'both')
    if (g > 0) call group_nodes(a, g, nodes)
    call report(g > 0, "body a has the group 'both'")
    if (g > 0) call report(size(nodes) == 1 .and. a%node_tag(nodes(1)) == 3, "'both' in a: the node of tag 3 only")
    g = group_index(a, 'diag')
    call report(g > 0, "body a has the curve 'diag' inside it")
    if (g > 0) then
      call group_nodes(a, g, nodes)
      call report(nodes_only(a, g) .and. .not. a%group(g)%point .and. size(nodes) == 2, &
                  "'diag': the nodes of an inside curve, no edge")
      if (size(nodes) == 2) call report(all(a%node_tag(nodes) == [1, 3]), "'diag': nodes of tags 1 and 3")
      call nodes_only_refusal(a, g, 'contact needs', s)
      call report(index(s, "group 'diag' is a curve inside the body") > 0, 'an inside curve is refused for contact: '//s)
    end if
    g = group_index(a, 'base')
    call report(g > 0, "body a has the curve 'base'")
    if (g > 0) then
      call group_nodes(a, g, nodes)
      call report(.not. nodes_only(a, g) .and. a%group(g)%nedge == 1 .and. size(nodes) == 2, &
                  "'base': its edge, and the point 'base' on its node")
      if (size(nodes) == 2) call report(all(a%node_tag(nodes) == [1, 2]), "'base': nodes of tags 1 and 2")
    end if
    call group_names(a, s)
    call report(index(s, "'corner' (point)") > 0 .and. index(s, "'diag' (inside the body)") > 0, &
                'group_names marks points and inside curves: '//s)
    call report(index(a%file_groups, 'physical points: corner free_pt both base') > 0, &
                'file_groups lists the physical points: '//a%file_groups)

    g = group_index(b, 'free_pt')
    call report(g > 0, "body b has 'free_pt' (a free node at its node's place)")
    if (g > 0) then
      call group_nodes(b, g, nodes)
      call report(size(nodes) == 1 .and. b%node_tag(nodes(1)) == 8, "'free_pt' is b's node of tag 8 (same place)")
    end if
    g = group_index(b, 'both')
    if (g > 0) call group_nodes(b, g, nodes)
    call report(g > 0, "body b has the group 'both'")
    if (g > 0) call report(size(nodes) == 1 .and. b%node_tag(nodes(1)) == 8, "'both' in b: the node of tag 8 only")
    call report(group_index(b, 'corner') == 0 .and. group_index(b, 'diag') == 0 .and. group_index(b, 'base') == 0, &
                "body b has neither 'corner' nor a's curves")
  end subroutine test_point_groups

  ! ---- small files ------------------------------------------------------------------------

  !> A unit square: nodes 1-4, the quadrangle 7 on surface 1 (physical "sq"), the line 8 on
  !! curve 1 (physical "base"). Line numbers: node 3's coordinates at 23, $Elements at 26,
  !! the quadrangle at 31.
  function square(format_line, node_lines, element_lines) result(l)
    character(len=*), intent(in), optional :: format_line
    character(len=*), intent(in), optional :: node_lines(:), element_lines(:)
    character(len=60), allocatable :: l(:)
    character(len=60) :: fl
    fl = '4.1 0 8'
    if (present(format_line)) fl = format_line
    l = [character(len=60) :: '$MeshFormat', fl, '$EndMeshFormat', &
         '$PhysicalNames', '2', '1 10 "base"', '2 20 "sq"', '$EndPhysicalNames', &
         '$Entities', '0 1 1 0', '1 0 0 0 1 0 0 1 10 0', '1 0 0 0 1 1 0 1 20 0', '$EndEntities']
    if (present(node_lines)) then
      l = [l, node_lines]
    else
      l = [l, [character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', '1', '2', '3', '4', &
                                    '0 0 0', '1 0 0', '1 1 0', '0 1 0', '$EndNodes']]
    end if
    if (present(element_lines)) then
      l = [l, element_lines]
    else
      l = [l, [character(len=60) :: '$Elements', '2 2 1 8', '1 1 1 1', '8 1 2', '2 1 3 1', &
                                    '7 1 2 3 4', '$EndElements']]
    end if
  end function square

  !> A fan of n triangles around node n + 1 (the largest tag) at the origin, nodes 1..n on
  !! the unit circle (counter-clockwise), triangle k = (k, k+1, n+1) with tag k; then the
  !! triangles of `extra` (tags n+1, n+2, ...), each given by its first node k.
  function fan(n, extra) result(l)
    integer, intent(in) :: n, extra(:)
    character(len=60), allocatable :: l(:)
    character(len=60) :: line
    integer :: k, e
    real(wp) :: t
    l = [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', '$PhysicalNames', '1', &
         '2 20 "sq"', '$EndPhysicalNames', '$Entities', '0 0 1 0', '1 -1 -1 0 1 1 0 1 20 0', '$EndEntities', &
         '$Nodes']
    write (line, '(a,i0,a,i0)') '1 ', n + 1, ' 1 ', n + 1
    l = [l, line]
    write (line, '(a,i0)') '2 1 0 ', n + 1
    l = [l, line]
    do k = 1, n + 1
      write (line, '(i0)') k
      l = [l, line]
    end do
    do k = 1, n
      t = 2.0_wp*acos(-1.0_wp)*real(k - 1, wp)/real(n, wp)
      write (line, '(2(es23.15,1x),a)') cos(t), sin(t), '0'
      l = [l, line]
    end do
    l = [character(len=60) :: l, '0 0 0', '$EndNodes', '$Elements']
    write (line, '(a,i0,a,i0,a,i0)') '1 ', n + size(extra), ' 1 ', n + size(extra)
    l = [l, line]
    write (line, '(a,i0)') '2 1 2 ', n + size(extra)
    l = [l, line]
    do k = 1, n
      write (line, '(4(i0,1x))') k, k, modulo(k, n) + 1, n + 1
      l = [l, line]
    end do
    do e = 1, size(extra)
      k = extra(e)
      write (line, '(4(i0,1x))') n + e, k, modulo(k, n) + 1, n + 1
      l = [l, line]
    end do
    l = [character(len=60) :: l, '$EndElements']
  end function fan

  !> The fan without duplicates is read: its 40 triangles around one node.
  subroutine read_ok_fan()
    type(mesh_t) :: m
    integer :: info
    character(len=512) :: msg
    call write_file(tmp//'fan40.msh', fan(40, [integer ::]))
    call msh_read(tmp//'fan40.msh', 'sq', 1, m, info, msg)
    call report(info == 0 .and. m%ncell == 40 .and. m%nnode == 41, 'a fan of 40 triangles at one node is read')
    if (info /= 0) write (*, '(a)') '      msg: '//trim(msg)
  end subroutine read_ok_fan

  subroutine test_bad_inputs()
    character(len=60), allocatable :: l(:)
    type(mesh_t) :: m
    integer :: info
    character(len=512) :: msg

    allocate (l(0))
    call msh_read(tmp//'missing.msh', 'sq', 3, m, info, msg)
    call report(info == 1 .and. index(msg, tmp//'missing.msh') > 0 .and. index(msg, 'body 3') > 0, &
                'a missing file is bad input naming it')
    write (*, '(a)') '      msg: '//trim(msg)

    call expect_error('binary.msh', square('4.1 1 8'), 'sq', 1, [character(len=20) :: 'binary', 'line 2'], &
                      'binary MSH is refused')
    call expect_error('v22.msh', [character(len=40) :: '$MeshFormat', '2.2 0 8', '$EndMeshFormat', &
                      '$Nodes', '1', '1 0 0 0', '$EndNodes'], 'sq', 1, &
                      [character(len=20) :: 'version 2.2', 'gmsh -format msh41', 'MshFileVersion'], &
                      'MSH 2.2 is refused, saying how to write 4.1')
    call expect_error('v40.msh', square('4 0 8'), 'sq', 1, [character(len=20) :: 'version 4 ', 'msh41'], &
                      'MSH 4.0 is refused')
    call expect_error('nonode.msh', square(element_lines=[character(len=60) :: '$Elements', '2 2 1 8', &
                      '1 1 1 1', '8 1 2', '2 1 3 1', '7 1 2 99 4', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: 'node 99', 'element 7', 'line 31'], 'a missing node is refused, with its element and line')
    call expect_error('hex.msh', square(element_lines=[character(len=60) :: '$Elements', '1 1 1 1', &
                      '3 1 5 1', '1 1 2 3 4 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: '3D', 'line 28'], 'a 3D element block is refused')
    call expect_error('tet.msh', square(element_lines=[character(len=60) :: '$Elements', '1 1 1 1', &
                      '2 1 4 1', '1 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: '3D', 'type 4'], 'a tetrahedron type is refused as 3D')
    call expect_error('z.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '1 1 0.5', '0 1 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: 'node 3', 'z =', '3D', 'line 23'], 'a node off z = 0 is refused')
    call expect_error('p2.msh', square(element_lines=[character(len=60) :: '$Elements', '1 1 1 1', &
                      '2 1 9 1', '1 1 2 3 4 1 2', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: 'type 9', 'first-order'], 'a second-order triangle is refused')
    call expect_error('region.msh', square(), 'nowhere', 1, [character(len=20) :: "'nowhere'", "'sq'"], &
                      'an unknown region is refused, listing the surfaces')
    call expect_error('nocell.msh', square(element_lines=[character(len=60) :: '$Elements', '1 1 8 8', &
                      '1 1 1 1', '8 1 2', '$EndElements']), 'sq', 1, [character(len=30) :: "'sq' has no triangles"], &
                      'a region without cells is refused')
    call expect_error('degenerate.msh', square(element_lines=[character(len=60) :: '$Elements', '1 2 41 42', &
                      '2 1 2 2', '41 1 2 3', '42 1 2 1', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: 'element 42', 'degenerate'], 'a degenerate triangle is refused by tag')
    call expect_error('flat.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '2 0 0', '0.5 1e-14 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: 'element 7', 'degenerate'], 'a nearly flat quadrangle is refused by tag')
    call expect_error('bowtie.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '2 1 0', '0 1 0', '$EndNodes'], &
                      element_lines=[character(len=60) :: '$Elements', '1 1 43 43', &
                      '2 1 3 1', '43 1 2 4 3', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: 'element 43', 'convex'], 'a self-crossing quadrangle is refused by tag')
    call expect_error('dart.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '0.3 0.3 0', '0 1 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: 'element 7', 'convex', 'node 3'], 'a re-entrant quadrangle is refused by tag')
    l = square()
    call expect_error('trunc_end.msh', l(1:size(l) - 1), 'sq', 1, [character(len=20) :: 'truncated', '$EndElements'], &
                      'a file cut before $EndElements is refused')
    call expect_error('trunc_nodes.msh', l(1:20), 'sq', 1, [character(len=20) :: 'truncated', '$Nodes'], &
                      'a file cut inside $Nodes is refused')
    call expect_error('no_elements.msh', l(1:25), 'sq', 1, [character(len=20) :: 'no $Elements'], &
                      'a file without $Elements is refused')
    call expect_error('count.msh', square(element_lines=[character(len=60) :: '$Elements', '2 3 1 8', &
                      '1 1 1 1', '8 1 2', '2 1 3 1', '7 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: '2 elements', '3 announced'], 'an element count mismatch is refused')
    call expect_error('word.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '1 one 0', '0 1 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: "'one'", 'line 23'], 'a word for a number is refused with its line')
    call expect_error('dup.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                      '1', '2', '2', '4', '0 0 0', '1 0 0', '1 1 0', '0 1 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: 'node tag 2', 'twice'], 'a repeated node tag is refused')
    call expect_error('absent.msh', square(element_lines=[character(len=60) :: '$Elements', '2 2 1 8', &
                      '1 1 1 1', '8 1 2', '2 1 3 1', '7 1 2 3 5', '$EndElements']), 'sq', 1, &
                      [character(len=20) :: 'node 5', 'not in $Nodes'], 'a reference to an absent node tag is refused')
    call expect_error('negative.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 -4 1 4', '2 1 0 4', &
                      '1', '2', '3', '4', '0 0 0', '1 0 0', '1 1 0', '0 1 0', '$EndNodes']), 'sq', 1, &
                      [character(len=20) :: 'number of nodes', '>= 0', "'-4'"], 'a negative count is refused')
    l = square()
    call expect_error('twice.msh', [l, l(14:25)], 'sq', 1, [character(len=24) :: 'second $Nodes', 'line 33'], &
                      'a second $Nodes section is refused')
    call expect_error('notmsh.msh', [character(len=20) :: 'hello', 'world'], 'sq', 1, &
                      [character(len=20) :: 'not a Gmsh MSH', 'line 1'], 'a file that is not MSH is refused')
    ! duplicates, tags and counts the file cannot hold
    call expect_error('dup_tri.msh', square(element_lines=[character(len=60) :: '$Elements', '1 3 1 9', &
                      '2 1 2 3', '7 1 2 3', '8 1 3 4', '9 3 1 2', '$EndElements']), 'sq', 1, &
                      [character(len=24) :: 'elements 7 and 9', 'same nodes'], 'a triangle listed twice (rotated) is refused')
    ! two triangles listed twice: the one of the smaller node list is named, whichever comes
    ! first in the file; around a node of few cells (compared pair by pair) and of many (sorted)
    call expect_error('dup_fan8.msh', fan(8, [5, 2]), 'sq', 1, &
                      [character(len=24) :: 'elements 2 and 10', 'same nodes'], &
                      'of two triangles listed twice, the smaller node list is named (8 cells at a node)')
    call expect_error('dup_fan40.msh', fan(40, [30, 7, 30, 7]), 'sq', 1, &
                      [character(len=24) :: 'elements 7 and 42', 'same nodes'], &
                      'of two triangles listed twice, the smaller node list is named (40 cells at a node)')
    call read_ok_fan()
    call expect_error('dup_line.msh', square(element_lines=[character(len=60) :: '$Elements', '2 3 1 9', &
                      '1 1 1 2', '8 1 2', '9 2 1', '2 1 3 1', '7 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=24) :: 'elements 8 and 9', "curve 'base'"], 'a boundary line listed twice is refused')
    call expect_error('tag0.msh', square(element_lines=[character(len=60) :: '$Elements', '2 2 1 8', &
                      '1 1 1 1', '8 1 2', '2 1 3 1', '0 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=24) :: 'element tag 0', 'must be >= 1'], 'an element tag 0 is refused')
    call expect_error('ref0.msh', square(element_lines=[character(len=60) :: '$Elements', '2 2 1 8', &
                      '1 1 1 1', '8 1 -1', '2 1 3 1', '7 1 2 3 4', '$EndElements']), 'sq', 1, &
                      [character(len=24) :: 'node tag -1', 'must be >= 1'], 'a node reference -1 is refused')
    l = square()
    l(10) = '0 1 99999 0'
    call expect_error('many_ents.msh', l, 'sq', 1, [character(len=24) :: 'announces 99999 surfaces', 'at most'], &
                      'more surfaces than the file can hold are refused before allocating')
    l = square()
    l(11) = '1 0 0 0 1 0 0 1 10 2000000000'
    call expect_error('many_bounds.msh', l, 'sq', 1, [character(len=24) :: '2000000000 bounding', 'curve 1'], &
                      'more bounding entities than the file can hold are refused')
  end subroutine test_bad_inputs

  subroutine test_unusual_inputs()
    type(mesh_t) :: m
    integer :: info, k, u, g
    character(len=512) :: msg
    character(len=32), parameter :: numbers(8) = [character(len=32) :: '0.1', '-2.5E+2', '1e-3', &
      '0.9999999999999998', '3.0000000000000004', '0.12345678901234567890123', '-7.25e-30', '+4']
    real(wp) :: want(8)
    character(len=32) :: nbuf
    logical :: read_all, all_exact
    real(wp), allocatable :: xy(:, :)
    character(len=60) :: one
    character(len=60), allocatable :: l(:)

    ! a clockwise quadrangle is accepted and reoriented, keeping its first vertex
    call write_file(tmp//'cw.msh', square(element_lines=[character(len=60) :: '$Elements', '1 1 7 7', &
                    '2 1 3 1', '7 1 4 3 2', '$EndElements']))
    call msh_read(tmp//'cw.msh', 'sq', 1, m, info, msg)
    call report(info == 0 .and. m%ncell == 1, 'a clockwise quadrangle is accepted')
    if (info == 0) call report(all(m%node_tag(m%cells(:, 1)) == [1, 2, 3, 4]) .and. area2(m, 1) > 0, &
                               'a clockwise quadrangle is reoriented counter-clockwise')

    ! sparse, unordered node tags in two blocks; a $Comments section and a $NodeData
    ! section with quoted strings are skipped; a missing region name picks the only surface
    call write_file(tmp//'sparse.msh', [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', &
      '$Comments', 'anything $Nodes 1 2', '$EndComments', &
      '$PhysicalNames', '2', '1 10 "base with blank"', '2 20 "sq"', '$EndPhysicalNames', &
      '$Entities', '0 1 1 0', '1 0 0 0 1 0 0 1 10 0', '1 0 0 0 1 1 0 1 20 0', '$EndEntities', &
      '$Nodes', '2 4 5 1000000', '1 1 1 2', '1000000', '5', '1 0 0 0.5', '0 0 0 0.0', &
      '2 1 1 2', '77', '12', '1 1 0 0.3 0.4', '0 1 0 0.1 0.2', '$EndNodes', &
      '$Elements', '2 2 1 8', '1 1 1 1', '8 5 1000000', '2 1 3 1', '7 1000000 77 12 5', '$EndElements', &
      '$NodeData', '1', '"a $view"', '0', '0', '$EndNodeData'])
    call msh_read(tmp//'sparse.msh', '', 1, m, info, msg)
    call report(info == 0, 'sparse unordered node tags and unknown sections are read')
    if (info /= 0) write (*, '(a)') trim(msg)
    if (info == 0) then
      call report(all(file_tags(m) == [5, 12, 77, 1000000]), 'the file order is by increasing tag')
      xy = file_order(m, m%xy)
      call report(all(xy(:, 1) == [0.0_wp, 0.0_wp]) .and. all(xy(:, 2) == [0.0_wp, 1.0_wp]) .and. &
                  all(xy(:, 3) == [1.0_wp, 1.0_wp]) .and. all(xy(:, 4) == [1.0_wp, 0.0_wp]), &
                  'sparse tags: coordinates follow their tags')
      call report(area2(m, 1) > 0 .and. abs(total_area(m) - 1) < 1e-15_wp, 'sparse tags: the cell, counter-clockwise')
      g = group_index(m, 'base with blank')
      call report(m%ngroup == 1 .and. g == 1, 'a physical name with a blank is kept')
      if (g == 1) call report(m%group(1)%nedge == 1 .and. all(m%node_tag(m%group(1)%edge(:, 1)) == [5, 1000000]), &
                              'the base edge oriented with the body on its left')
    end if

    ! a node tag outside the range $Nodes announces (1..4 here, tag 9) is still found
    call write_file(tmp//'range.msh', square(node_lines=[character(len=60) :: '$Nodes', '1 4 1 4', '2 1 0 4', &
                    '1', '2', '9', '4', '0 0 0', '1 0 0', '1 1 0', '0 1 0', '$EndNodes'], &
                    element_lines=[character(len=60) :: '$Elements', '2 2 1 8', '1 1 1 1', '8 1 2', &
                    '2 1 3 1', '7 1 2 9 4', '$EndElements']))
    call msh_read(tmp//'range.msh', 'sq', 1, m, info, msg)
    call report(info == 0, 'a node tag beyond the announced range is read')
    if (info == 0) call report(all(file_tags(m) == [1, 2, 4, 9]) .and. all(m%xy(:, findloc(m%node_tag, 9, dim=1)) == 1.0_wp) .and. &
                               abs(total_area(m) - 1) < 1e-15_wp, 'the node of tag 9 has its coordinates')

    call expect_error('skipline.msh', [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', &
      '$Comments', 'a', 'b', '$EndComments', '$Nodes', '1 1 1 1', '2 1 0 1', '1', '0 0 0', '$EndNodes', &
      '$Elements', '1 1 1 1', '2 1 2 1', '1 1 1 5', '$EndElements'], '', 1, &
      [character(len=20) :: 'node 5', 'line 17'], 'line numbers count across skipped sections')

    ! a mixed mesh without physical groups: every 2D element, a triangle has cells(4,c) = 0
    call write_file(tmp//'mixed.msh', [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', &
      '$Nodes', '1 5 1 5', '2 1 0 5', '1', '2', '3', '4', '5', &
      '0 0 0', '1 0 0', '1 1 0', '0 1 0', '2 0.5 0', '$EndNodes', &
      '$Elements', '2 2 1 2', '2 1 3 1', '1 1 2 3 4', '2 1 2 1', '2 2 5 3', '$EndElements'])
    call msh_read(tmp//'mixed.msh', '', 1, m, info, msg)
    call report(info == 0, 'a mesh without physical groups is read whole')
    if (info == 0) call report(m%element == ELEM_MIXED .and. m%nvert == 4 .and. m%ncell == 2 .and. &
                               all(m%cell_type == [ELEM_Q1, ELEM_P1]) .and. m%cells(4, 2) == 0 .and. &
                               m%ngroup == 0 .and. abs(total_area(m) - 1.5_wp) < 1e-15_wp, &
                               'mixed mesh: ELEM_MIXED, triangle with cells(4,c) = 0, area 1.5')

    ! numbers in every form are read exactly as a formatted READ reads them: triangle k has
    ! the nodes (0,0), (1,0) and (number k, 1), each its own, and is the physical surface 'tk'
    ! (a body is one connected piece: each triangle is read as its own body)
    l = [character(len=60) :: '$MeshFormat', '4.1 0 8', '$EndMeshFormat', '$PhysicalNames', '8']
    do k = 1, 8
      one = '2 '//i2s(k)//' "t'//i2s(k)//'"'
      l = [l, one]
    end do
    l = [l, [character(len=60) :: '$EndPhysicalNames', '$Entities', '0 0 8 0']]
    do k = 1, 8
      one = i2s(k)//' -300 -1 0 300 2 0 1 '//i2s(k)//' 0'
      l = [l, one]
    end do
    l = [l, [character(len=60) :: '$EndEntities', '$Nodes', '1 24 1 24', '2 1 0 24']]
    do k = 1, 24
      one = i2s(k)
      l = [l, one]
    end do
    do k = 1, 8
      nbuf = numbers(k)
      read (nbuf, *) want(k)
      one = trim(numbers(k))//' 1 0'
      l = [l, [character(len=60) :: '0 0 0', '1 0 0'], one]
    end do
    l = [l, [character(len=60) :: '$EndNodes', '$Elements', '8 8 1 8']]
    do k = 1, 8
      one = '2 '//i2s(k)//' 2 1'
      l = [l, one]
      one = i2s(k)//' '//i2s(3*k - 2)//' '//i2s(3*k - 1)//' '//i2s(3*k)
      l = [l, one]
    end do
    l = [l, [character(len=60) :: '$EndElements']]
    call write_file(tmp//'numbers.msh', l)
    read_all = .true.
    all_exact = .true.
    do k = 1, 8
      call msh_read(tmp//'numbers.msh', 't'//i2s(k), 1, m, info, msg)
      if (info /= 0) then
        read_all = .false.
        write (*, '(a)') trim(msg)
        exit
      end if
      all_exact = all_exact .and. m%nnode == 3 .and. count(m%xy(1, :) == want(k)) == 1
    end do
    call report(read_all, 'a file with numbers in every form is read')
    if (read_all) call report(all_exact, &
                              'reals: exactly what a formatted READ gives (0.1, -2.5E+2, 17 and 23 digits, 1e-30, +4)')
    do k = 1, 4
      open (newunit=u, file=tmp//trim(word('cw sparse mixed numbers', k))//'.msh')
      close (u, status='delete')
    end do
  end subroutine test_unusual_inputs

  ! ---- benchmark ----------------------------------------------------------------------------

  subroutine bench(path)
    character(len=*), intent(in) :: path
    type(mesh_t) :: m
    integer :: info
    integer(8) :: t0, t1, rate
    character(len=512) :: msg, region
    region = ''
    if (command_argument_count() >= 2) call get_command_argument(2, region)
    call system_clock(t0, rate)
    call msh_read(path, trim(region), 1, m, info, msg)
    call system_clock(t1)
    if (info /= 0) then
      write (*, '(a)') trim(msg)
      error stop 1
    end if
    write (*, '(a,i0,a,i0,a,i0,a,i0,a,f8.3,a)') 'read ', m%nnode, ' nodes (', 2*m%nnode, ' DOFs), ', &
      m%ncell, ' cells, ', m%ngroup, ' groups in ', real(t1 - t0, wp)/real(rate, wp), ' s'
  end subroutine bench

end program test_gmsh
