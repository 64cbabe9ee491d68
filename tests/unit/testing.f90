!> Helpers shared by the Fortran test programs: PASS/FAIL reporting with counters and
!! the closing line; writing a test's input file; an independent direct solve of an
!! assembled body (LAPACK band Cholesky in the natural order) so the FE tests do not
!! depend on the Cholesky module that other tests check; the bodies of the ordering test
!! and benchmark (a rectangle on its structured mesh, the same on a general,
!! unstructured-looking mesh, the ordering of either; a solid box); for the MPRGP tests and benchmark,
!! the 1D obstacle problem, seeded random SPD matrices and one solve by a fresh solver.
module testing
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use kinds, only: wp
  use space, only: NDIM, node_dof
  use config, only: body_cfg_t, traction_cfg_t, boundary_cfg_t, SIDE_TOP, SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT, MAX_SIDES
  use mesh, only: mesh_t, mesh_build, box_build, side_nodes
  use elements_3d, only: kuhn_tets
  use elements, only: MAX_NVERT, MAX_NDOF, element_stiffness
  use assembly, only: body_system_t, expand, assemble_body, lame_parameters
  use linop, only: linop_t, csc_op_t, csc_op_init
  use mprgp, only: mprgp_t, mprgp_opts_t, mprgp_stats_t, MPRGP_BAD_ARG
  use lapack, only: dpbsv, dgesv
  use ordering, only: grid_dissection, coordinate_bisection
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_METIS, ORD_AMD, ORD_GIVEN
  use errors, only: error_t
  implicit none (type, external)
  private

  integer, public, protected :: npass = 0   !< checks passed so far
  integer, public, protected :: nfail = 0   !< checks failed so far

  public :: report, report_le, test_summary, write_file, band_solve, solve_full, obstacle_problem
  public :: rectangle_body, structured_body, general_body, side_free_dofs, order_body, factor_ordered, box_system
  public :: set_seed, urand, random_spd, spd_from_eigs, solve_once
  public :: random_bounds, enumerate_box, box_projected, identity
  public :: error_parts, grid_mesh, grid_mesh_parts, box_mesh_parts, file_bytes, scratch_path, fresh_folder

contains

  !> Print one check as `PASS  what (value, tol)`, `PASS  what (value)` or `FAIL  ...`
  !! and count it.
  subroutine report(ok, what, value, tol)
    logical, intent(in) :: ok                         !< outcome
    character(len=*), intent(in) :: what              !< what was checked
    real(wp), intent(in), optional :: value, tol      !< measured value and its tolerance
    character(len=64) :: extra
    extra = ''
    if (present(value) .and. present(tol)) then
      write (extra, '(a,es9.2,a,es9.2,a)') ' (', value, ', tol ', tol, ')'
    else if (present(value)) then
      write (extra, '(a,es9.2,a)') ' (', value, ')'
    end if
    if (ok) then
      npass = npass + 1
      write (output_unit, '(a)') 'PASS  '//what//trim(extra)
    else
      nfail = nfail + 1
      write (output_unit, '(a)') 'FAIL  '//what//trim(extra)
    end if
  end subroutine report

  !> A check that value <= tol (a NaN fails).
  subroutine report_le(value, tol, what)
    real(wp), intent(in) :: value, tol  !< measured value, tolerance
    character(len=*), intent(in) :: what  !< what was checked
    call report(value <= tol, what, value, tol)
  end subroutine report_le

  !> Print `N checks passed, M failed` and stop with status 1 if anything failed.
  subroutine test_summary()
    write (output_unit, '(i0,a,i0,a)') npass, ' checks passed, ', nfail, ' failed'
    if (nfail > 0) error stop 1
  end subroutine test_summary

  !> Write `lines` to the file `path` (replacing it), one trimmed line each.
  subroutine write_file(path, lines)
    character(len=*), intent(in) :: path          !< file to write
    character(len=*), intent(in) :: lines(:)      !< its lines
    integer :: u, k
    open (newunit=u, file=path, status='replace', action='write')
    do k = 1, size(lines)
      write (u, '(a)') trim(lines(k))
    end do
    close (u)
  end subroutine write_file

  !> A path for a test's files beside the folder of the running test program
  !! (build/<kind>/name for build/<kind>/tests/test_x), so that a release and a checked
  !! `make check` running at once share none; `name` in the current folder when the program
  !! was started without a path.
  function scratch_path(name) result(path)
    character(len=*), intent(in) :: name   !< a file or folder name, e.g. 'test-files'
    character(len=:), allocatable :: path
    character(len=4096) :: arg
    integer :: k
    call get_command_argument(0, arg)
    k = index(arg, '/', back=.true.)
    if (k == 0) then
      path = name
    else
      path = arg(1:k)//'../'//name
    end if
  end function scratch_path

  !> Remove the folder `dir` with what it holds, and make it anew (empty).
  subroutine fresh_folder(dir)
    character(len=*), intent(in) :: dir   !< the folder (from scratch_path)
    integer :: rc
    call execute_command_line("rm -rf '"//dir//"' && mkdir -p '"//dir//"'", exitstat=rc)
    if (rc /= 0) error stop 'fresh_folder: cannot make '//dir
  end subroutine fresh_folder

  !> The whole file as bytes ('' when it cannot be read).
  function file_bytes(path) result(b)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: b
    integer :: u, n, ios
    b = ''
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    inquire (unit=u, size=n)
    deallocate (b)
    allocate (character(len=n) :: b)
    if (n > 0) read (u, iostat=ios) b
    close (u)
  end function file_bytes

  !> Solve K u = f on the free DOFs with LAPACK's banded Cholesky (natural order);
  !! stops the test program if the matrix is not positive definite.
  subroutine band_solve(sys, x)
    type(body_system_t), intent(in) :: sys  !< assembled body
    real(wp), intent(out) :: x(:)           !< solution at the free DOFs
    real(wp), allocatable :: ab(:, :)
    integer :: kd, i, j, p, info
    kd = 0
    do j = 1, sys%n
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        i = sys%rowind(p) + 1
        kd = max(kd, j - i)
      end do
    end do
    allocate (ab(kd + 1, sys%n))
    ab = 0.0_wp
    do j = 1, sys%n
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        i = sys%rowind(p) + 1
        if (i <= j) ab(kd + 1 + i - j, j) = sys%val(p)
      end do
    end do
    x(1:sys%n) = sys%f
    call dpbsv('U', sys%n, kd, 1, ab, kd + 1, x, sys%n, info)
    if (info /= 0) then
      write (*, '(a,i0)') 'FAIL  dpbsv info = ', info
      error stop 1
    end if
  end subroutine band_solve

  !> The displacement at every DOF of an assembled body (banded solve, then the prescribed
  !! values filled in); stops the test program with `what` and msg if info /= 0 (a failed
  !! mesh or assembly before it).
  subroutine solve_full(sys, info, msg, what, u_full)
    type(body_system_t), intent(in) :: sys              !< assembled body
    integer, intent(in) :: info                         !< status of the mesh and assembly
    character(len=*), intent(in) :: msg, what           !< their message, and what they were
    real(wp), allocatable, intent(out) :: u_full(:)     !< displacement at all DOFs
    real(wp), allocatable :: x(:)
    if (info /= 0) then
      write (*, '(a)') 'FAIL  '//what//': '//trim(msg)
      error stop 1
    end if
    allocate (x(sys%n), u_full(sys%ndof))
    call band_solve(sys, x)
    call expand(sys, x, u_full)
  end subroutine solve_full

  !> 1D obstacle problem: -u'' = -15 on (0,1), u(0) = u(1) = 0, u >= -1 (flat
  !! obstacle), by finite differences: A = tridiag(-1,2,-1)*(n+1)^2*scale_a in CSC,
  !! b = -15, l = -1. Exact solution for scale_a = 1: u = 7.5 x^2 - 15 a x on [0,a],
  !! -1 on [a,1-a], symmetric, a = sqrt(2/15).
  subroutine obstacle_problem(n, op, b, l, scale_a)
    integer, intent(in) :: n                          !< number of interior grid points
    type(csc_op_t), intent(out) :: op                 !< the matrix A
    real(wp), allocatable, intent(out) :: b(:), l(:)  !< right-hand side and lower bound
    real(wp), intent(in) :: scale_a                   !< factor applied to A
    integer, allocatable :: cp(:), ri(:)
    real(wp), allocatable :: v(:)
    integer :: j, k
    type(error_t) :: err
    real(wp) :: h2
    h2 = real(n + 1, wp)**2
    allocate (cp(n + 1), ri(3 * n), v(3 * n))
    k = 0
    cp(1) = 0
    do j = 1, n
      if (j > 1) then
        k = k + 1; ri(k) = j - 2; v(k) = -h2 * scale_a
      end if
      k = k + 1; ri(k) = j - 1; v(k) = 2.0_wp * h2 * scale_a
      if (j < n) then
        k = k + 1; ri(k) = j; v(k) = -h2 * scale_a
      end if
      cp(j + 1) = k
    end do
    call csc_op_init(op, n, cp, ri, v, err)
    if (err%failed()) error stop 'csc_op_init failed: '//err%text()
    allocate (b(n), l(n))
    b = -15.0_wp
    l = -1.0_wp
  end subroutine obstacle_problem

  !> A 2 x 1 rectangle at the origin (steel: E = 2.1e11, nu = 0.3) with nx x ny cells of
  !! the element `element` and the side conditions `bcs` (left, right, bottom, top).
  function rectangle_body(nx, ny, element, bcs) result(b)
    integer, intent(in) :: nx, ny       !< grid cells along x and y
    integer, intent(in) :: element      !< ELEM_Q1 or ELEM_P1
    integer, intent(in) :: bcs(4)       !< BC_* of each side
    type(body_cfg_t) :: b
    b%id = 1
    b%x0 = 0.0_wp
    b%y0 = 0.0_wp
    b%width = 2.0_wp
    b%height = 1.0_wp
    b%nx = nx
    b%ny = ny
    b%element = element
    b%young = 2.1e11_wp
    b%poisson = 0.3_wp
    b%bc(1:4) = bcs
  end function rectangle_body

  !> The load of the ordering bodies: on b's top side the traction t0 + t1 x, (1, -3) MPa
  !! at x = 0 and (0, -1) MPa more per metre.
  function top_traction(b) result(tr)
    type(body_cfg_t), intent(in) :: b   !< the body
    type(traction_cfg_t) :: tr
    tr%body = b%id
    tr%side = SIDE_TOP
    tr%t0(1:2) = [1.0e6_wp, -3.0e6_wp]
    tr%t1(1:2) = [0.0_wp, -1.0e6_wp]
  end function top_traction

  !> The structured mesh of `b` and its system, its top loaded by a linear traction (that
  !! of general_body); `last` = the free normal (y) DOFs of the bottom side. Stops the test
  !! program on failure.
  subroutine structured_body(b, msh, sys, last)
    type(body_cfg_t), intent(in) :: b                 !< geometry, grid, element, sides
    type(mesh_t), intent(out) :: msh                  !< the structured mesh
    type(body_system_t), intent(out) :: sys           !< its assembled system
    integer, allocatable, intent(out) :: last(:)      !< interface DOFs (bottom side, y)
    type(traction_cfg_t) :: tr(1)
    integer :: info
    character(len=256) :: msg
    type(error_t) :: err
    tr(1) = top_traction(b)
    call grid_mesh_parts(msh, b, info, msg)
    if (info /= 0) error stop 'structured_body: mesh_build failed: '//trim(msg)
    call assemble_body(msh, b, .true., tr, 1, sys, err)
    if (err%failed()) error stop 'structured_body: assemble_body failed: '//err%text()
    last = side_free_dofs(msh, sys, SIDE_BOTTOM, 2)
  end subroutine structured_body

  !> The free DOFs of component `component` (1 = x, 2 = y) of the nodes on one side of a
  !! structured mesh, along the side (side 0: none).
  function side_free_dofs(msh, sys, side, component) result(idx)
    type(mesh_t), intent(in) :: msh               !< a structured mesh
    type(body_system_t), intent(in) :: sys        !< its system
    integer, intent(in) :: side                   !< SIDE_*, or 0
    integer, intent(in) :: component              !< 1 or 2
    integer, allocatable :: idx(:)
    integer, allocatable :: nodes(:)
    integer :: k, f
    allocate (idx(0))
    if (side == 0) return
    call side_nodes(msh, side, nodes)
    do k = 1, size(nodes)
      f = sys%free_of(2*(nodes(k) - 1) + component)
      if (f > 0) idx = [idx, f]
    end do
  end function side_free_dofs

  !> A solid box, the unit cube at the origin (steel: E = 2.1e11, nu = 0.3) with nx x ny x nz
  !! grid cells of hexahedra (ELEM_Q1) or tetrahedra (ELEM_P1), side conditions `bcs` (left,
  !! right, bottom, top, front, back), its top (y = 1) loaded by (0, -1, 0) MPa; `last` = the
  !! free normal (y) DOFs of the top side, the contact face. The run's dimension must be 3
  !! (space::set_dimension). Stops the program on failure.
  subroutine box_system(nx, ny, nz, element, bcs, msh, sys, last)
    integer, intent(in) :: nx, ny, nz                 !< grid cells along x, y, z
    integer, intent(in) :: element                    !< ELEM_Q1 or ELEM_P1
    integer, intent(in) :: bcs(MAX_SIDES)             !< BC_* of each side
    type(mesh_t), intent(out) :: msh                  !< the box's mesh
    type(body_system_t), intent(out) :: sys           !< its assembled system
    integer, allocatable, intent(out) :: last(:)      !< interface DOFs (top side, y)
    type(body_cfg_t) :: b
    type(traction_cfg_t) :: tr(1)
    integer, allocatable :: nodes(:)
    integer :: info, k, f
    character(len=256) :: msg
    type(error_t) :: err
    if (NDIM /= 3) error stop 'box_system: the dimension is not 3 (space::set_dimension)'
    b%id = 1
    b%x0 = 0.0_wp
    b%y0 = 0.0_wp
    b%z0 = 0.0_wp
    b%width = 1.0_wp
    b%height = 1.0_wp
    b%depth = 1.0_wp
    b%nx = nx
    b%ny = ny
    b%nz = nz
    b%element = element
    b%young = 2.1e11_wp
    b%poisson = 0.3_wp
    b%bc = bcs
    tr(1)%body = 1
    tr(1)%side = SIDE_TOP
    tr(1)%t0 = [0.0_wp, -1.0e6_wp, 0.0_wp]
    call box_mesh_parts(msh, b, info, msg)
    if (info /= 0) error stop 'box_system: box_build failed: '//trim(msg)
    call assemble_body(msh, b, .true., tr, 1, sys, err)
    if (err%failed()) error stop 'box_system: assemble_body failed: '//err%text()
    call side_nodes(msh, SIDE_TOP, nodes)
    allocate (last(0))
    do k = 1, size(nodes)
      f = sys%free_of(node_dof(nodes(k), 2))
      if (f > 0) last = [last, f]
    end do
  end subroutine box_system

  !> The nested-dissection order of a body's free DOFs not in `last`, as the program takes
  !! it (module condense): along the grid lines of a structured mesh, by coordinate
  !! bisection on any other.
  subroutine order_body(msh, sys, last, perm, info, msg)
    type(mesh_t), intent(in) :: msh                   !< the body's mesh
    type(body_system_t), intent(in) :: sys            !< its system (with its pattern on a general mesh)
    integer, intent(in) :: last(:)                    !< free DOFs ordered last by the caller
    integer, allocatable, intent(out) :: perm(:)      !< the interior order
    integer, intent(out) :: info                      !< 0, or the error's category
    character(len=*), intent(out) :: msg              !< the failure, else blank
    type(error_t) :: err
    if (msh%structured) then
      call grid_dissection(msh%nx, msh%ny, sys%free_of, sys%n, last, perm, err)
    else
      call coordinate_bisection(msh%xy, sys%free_of, sys%dof_of, sys%colptr, sys%rowind, last, perm, err)
    end if
    call error_parts(err, info, msg)
  end subroutine order_body

  !> A body on a general mesh, as a mesh file would give it: the structured mesh of `b`
  !! with its nodes renumbered at random, every interior node moved by up to `perturb`
  !! cell sizes in x and y, structured = .false., nx = ny = 0; the stiffness assembled
  !! here from the cells (module assembly still builds its pattern from the grid), the
  !! load of b's top traction carried over, the prescribed DOFs those of `b`'s sides.
  !! `last` = the free normal (y) DOFs of the bottom side, the contact interface.
  subroutine general_body(b, perturb, seed, msh, sys, last)
    type(body_cfg_t), intent(in) :: b                 !< geometry, grid, element, sides
    real(wp), intent(in) :: perturb                   !< largest node move [cell sizes], < 0.5
    integer, intent(in) :: seed                       !< seed of the renumbering and moves
    type(mesh_t), intent(out) :: msh                  !< the general mesh
    type(body_system_t), intent(out) :: sys           !< its system (all fields but u_fixed, f_applied)
    integer, allocatable, intent(out) :: last(:)      !< interface DOFs (bottom side, y)
    type(mesh_t) :: grid
    type(body_cfg_t) :: free
    type(traction_cfg_t) :: tr(1)
    type(boundary_cfg_t) :: bd(4)
    integer, allocatable :: new_of(:), bottom(:)
    integer :: info, k, j, i, t, nn, q, g, side, nbd
    integer(int64) :: state
    real(wp) :: hx, hy
    character(len=256) :: msg
    type(error_t) :: err

    tr(1) = top_traction(b)
    call grid_mesh_parts(grid, b, info, msg)
    if (info /= 0) error stop 'general_body: mesh_build failed: '//trim(msg)
    nn = grid%nnode

    ! a random renumbering (Fisher-Yates with the Park-Miller generator)
    state = modulo(int(seed, int64)*16807_int64 + 12345_int64, 2147483646_int64) + 1_int64
    new_of = [(k, k=1, nn)]
    do k = nn, 2, -1
      j = 1 + int(modulo(next(), int(k, int64)))
      t = new_of(k)
      new_of(k) = new_of(j)
      new_of(j) = t
    end do

    msh%element = grid%element
    msh%nvert = grid%nvert
    msh%nnode = nn
    msh%ncell = grid%ncell
    msh%structured = .false.
    msh%nx = 0
    msh%ny = 0
    msh%source = 'general_body'
    allocate (msh%xy(2, nn), msh%cells(grid%nvert, grid%ncell))
    hx = grid%width/real(grid%nx, wp)
    hy = grid%height/real(grid%ny, wp)
    do k = 1, nn
      msh%xy(:, new_of(k)) = grid%xy(:, k)
      i = mod(k - 1, grid%nx + 1)
      j = (k - 1)/(grid%nx + 1)
      if (i > 0 .and. i < grid%nx .and. j > 0 .and. j < grid%ny) then
        msh%xy(1, new_of(k)) = msh%xy(1, new_of(k)) + perturb*hx*(2.0_wp*uniform() - 1.0_wp)
        msh%xy(2, new_of(k)) = msh%xy(2, new_of(k)) + perturb*hy*(2.0_wp*uniform() - 1.0_wp)
      end if
    end do
    msh%cells = reshape(new_of(reshape(grid%cells, [size(grid%cells)])), shape(grid%cells))
    msh%cell_type = grid%cell_type
    msh%node_tag = [(k, k=1, nn)]
    msh%cell_tag = grid%cell_tag

    ! the grid's sides as groups of the general mesh, its side conditions as &boundary
    ! conditions and its top traction as a group traction: assemble_body on any mesh
    msh%ngroup = grid%ngroup
    msh%group = grid%group
    do g = 1, msh%ngroup
      msh%group(g)%edge = reshape(new_of(reshape(grid%group(g)%edge, [2*grid%group(g)%nedge])), &
                                  [2, grid%group(g)%nedge])
    end do
    msh%file_groups = grid%file_groups
    nbd = 0
    do side = 1, 4
      select case (b%bc(side))
      case (BC_CLAMPED, BC_DISPLACEMENT)
        nbd = nbd + 1
        bd(nbd)%fix = .true.
        bd(nbd)%u(1:2) = merge(b%u_side(1:2, side), [0.0_wp, 0.0_wp], b%bc(side) == BC_DISPLACEMENT)
      case (BC_ROLLER)
        nbd = nbd + 1
        bd(nbd)%fix(1:2) = [side == SIDE_LEFT .or. side == SIDE_RIGHT, side == SIDE_BOTTOM .or. side == SIDE_TOP]
      case default
        cycle
      end select
      bd(nbd)%body = b%id
      bd(nbd)%group = trim(grid%group(side)%name)
    end do
    free = b
    free%bc = BC_FREE
    tr(1)%side = 0
    tr(1)%group = 'top'
    tr(1)%tx = tr(1)%t1
    tr(1)%t1 = 0.0_wp
    call assemble_body(msh, free, .true., tr, 1, sys, err, boundaries=bd(1:nbd))
    if (err%failed()) error stop 'general_body: assemble_body failed on the general mesh: '//err%text()

    call side_nodes(grid, SIDE_BOTTOM, bottom)
    allocate (last(0))
    do k = 1, size(bottom)
      q = sys%free_of(2*(new_of(bottom(k)) - 1) + 2)
      if (q > 0) last = [last, q]
    end do

  contains

    integer(int64) function next()
      state = modulo(state*48271_int64, 2147483647_int64)
      next = state
    end function next

    real(wp) function uniform()
      uniform = real(next(), wp)/2147483647.0_wp
    end function uniform


  end subroutine general_body

  !> Factor a body's stiffness by CHOLMOD with its interface DOFs `last` ordered last, in
  !! ordering o: 1 METIS, 2 AMD, 3 the given interior permutation `perm` (order_body).
  subroutine factor_ordered(ch, sys, o, last, perm, info, msg)
    type(chol_t), intent(inout) :: ch
    type(body_system_t), intent(in) :: sys
    integer, intent(in) :: o
    integer, intent(in) :: last(:), perm(:)
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(error_t) :: err
    select case (o)
    case (1)
      call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_METIS, err, last=last)
    case (2)
      call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_AMD, err, last=last)
    case default
      call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, last=last, &
                     interior_perm=perm)
    end select
    info = merge(1, 0, err%failed())
    msg = err%text()
  end subroutine factor_ordered

  ! ---- random dense QPs and one MPRGP solve (the MPRGP tests)

  !> Seed the intrinsic generator with s, s + 7919, s + 2*7919, ... so that a test's random
  !! problems are the same on every run.
  subroutine set_seed(s)
    integer, intent(in) :: s    !< the seed
    integer :: n, k
    integer, allocatable :: put(:)
    call random_seed(size=n)
    allocate (put(n))
    put = [(s + 7919*k, k=1, n)]
    call random_seed(put=put)
  end subroutine set_seed

  !> A uniform random number in [lo, hi).
  real(wp) function urand(lo, hi)
    real(wp), intent(in) :: lo, hi  !< the interval
    real(wp) :: r
    call random_number(r)
    urand = lo + (hi - lo) * r
  end function urand

  !> The n x n identity matrix.
  pure function identity(n) result(a)
    integer, intent(in) :: n
    real(wp) :: a(n, n)
    integer :: i
    a = 0.0_wp
    do i = 1, n
      a(i, i) = 1.0_wp
    end do
  end function identity

  !> Random SPD matrix Q diag(d) Q' with log-uniform eigenvalues in [1, 10**cexp]
  !! (the extremes 1 and 10**cexp included when n >= 2).
  subroutine random_spd(n, cexp, a, lmin, lmax)
    integer, intent(in) :: n                          !< order
    real(wp), intent(in) :: cexp                      !< log10 of the condition number
    real(wp), intent(out) :: a(n, n), lmin, lmax      !< the matrix, its extreme eigenvalues
    real(wp) :: d(n)
    integer :: i
    do i = 1, n
      d(i) = 10.0_wp**(cexp * urand(0.0_wp, 1.0_wp))
    end do
    if (n >= 2) then
      d(1) = 1.0_wp
      d(2) = 10.0_wp**cexp
    end if
    call spd_from_eigs(n, d, a)
    lmin = minval(d)
    lmax = maxval(d)
  end subroutine random_spd

  !> Symmetric matrix Q diag(d) Q' with given eigenvalues d; Q is a product of three
  !! random Householder reflectors.
  subroutine spd_from_eigs(n, d, a)
    integer, intent(in) :: n            !< order
    real(wp), intent(in) :: d(n)        !< eigenvalues
    real(wp), intent(out) :: a(n, n)    !< the matrix
    real(wp) :: q(n, n), v(n), qv(n), vv
    integer :: i, j, k
    q = 0.0_wp
    do i = 1, n
      q(i, i) = 1.0_wp
    end do
    do k = 1, 3
      do i = 1, n
        v(i) = urand(-1.0_wp, 1.0_wp)
      end do
      ! q := q (I - 2 v v'/v'v)
      qv = matmul(q, v)
      vv = dot_product(v, v)
      do j = 1, n
        q(:, j) = q(:, j) - (2.0_wp * v(j) / vv) * qv
      end do
    end do
    do i = 1, n
      a(:, i) = matmul(q, d * q(i, :))
    end do
    a = 0.5_wp * (a + transpose(a))
  end subroutine spd_from_eigs

  !> One solve by a fresh solver with the options opts: x in/out, st its outcome; g = A x - b
  !! and ax = A x at the returned x when asked for (ax in: A x at the warm start, with
  !! opts%use_ax); the ring of stored directions rw, raw, nrw when given.
  subroutine solve_once(op, b, l, x, opts, st, g, ax, rw, raw, nrw)
    class(linop_t), intent(inout) :: op                 !< the matrix A
    real(wp), intent(in) :: b(:), l(:)                  !< right-hand side, lower bounds
    real(wp), intent(inout) :: x(:)                     !< start in, solution out
    type(mprgp_opts_t), intent(in) :: opts              !< solver options
    type(mprgp_stats_t), intent(out) :: st              !< the solve's outcome
    real(wp), intent(out), optional :: g(:)             !< gradient at the returned x
    real(wp), intent(inout), optional :: ax(:)          !< A x at the start in, at the end out
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)  !< stored directions, their images
    integer, intent(inout), optional :: nrw(2)          !< ring count and position
    type(mprgp_t) :: solver
    solver%opts = opts
    if (present(ax)) solver%ax = ax
    call solver%solve(op, b, l, x, rw, raw, nrw)
    st = solver%stats
    if (st%status == MPRGP_BAD_ARG) return
    if (present(g)) g = solver%g
    if (present(ax)) ax = solver%ax
  end subroutine solve_once

  !> An error_t as the tests read it: info its category (0 when none), msg its message.
  subroutine error_parts(err, info, msg)
    type(error_t), intent(in) :: err       !< the error, possibly none
    integer, intent(out) :: info           !< err%category
    character(len=*), intent(out) :: msg   !< err%text()
    info = err%category
    msg = err%text()
  end subroutine error_parts

  !> mesh_build of a grid the test knows to be valid: stops the test program when it fails.
  subroutine grid_mesh(m, body)
    type(mesh_t), intent(out) :: m
    type(body_cfg_t), intent(in) :: body
    type(error_t) :: err
    call mesh_build(m, body, err)
    if (err%failed()) error stop 'grid_mesh: mesh_build failed: '//err%text()
  end subroutine grid_mesh

  !> mesh_build with its outcome as (category, message): info 0 on success.
  subroutine grid_mesh_parts(m, body, info, msg)
    type(mesh_t), intent(out) :: m
    type(body_cfg_t), intent(in) :: body
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(error_t) :: err
    call mesh_build(m, body, err)
    call error_parts(err, info, msg)
  end subroutine grid_mesh_parts

  !> box_build (Kuhn's tetrahedra) with its outcome as (category, message): info 0 on success.
  subroutine box_mesh_parts(m, body, info, msg)
    type(mesh_t), intent(out) :: m
    type(body_cfg_t), intent(in) :: body
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    type(error_t) :: err
    call box_build(m, body, kuhn_tets, err)
    call error_parts(err, info, msg)
  end subroutine box_mesh_parts


  ! ---- bound-constrained QPs: random bounds, the solution by enumeration, the projected gradient

  !> Random bounds for variable i around the value t with spread w: kind 0 none, 1 lower
  !! only, 2 upper only, 3 a box, 4 fixed (l = u).
  subroutine random_bounds(kind, t, w, l, u)
    integer, intent(in) :: kind
    real(wp), intent(in) :: t, w
    real(wp), intent(out) :: l, u
    l = -huge(1.0_wp)
    u = huge(1.0_wp)
    select case (kind)
    case (1)
      l = t + urand(-1.0_wp, 1.0_wp) * w
    case (2)
      u = t + urand(-1.0_wp, 1.0_wp) * w
    case (3)
      l = t + urand(-1.0_wp, 0.5_wp) * w
      u = l + urand(0.0_wp, 1.0_wp) * w
    case (4)
      l = t + urand(-1.0_wp, 1.0_wp) * w
      u = l
    end select
  end subroutine random_bounds


  !> The solution of min 1/2 x'Hx - c'x, l <= x <= u, G x = e (r = size(e) rows, r = 0:
  !! none) by enumeration of every assignment of the variables to free / at l / at u (a
  !! KKT solve each): the assignment whose KKT point violates feasibility and the signs of
  !! the bound multipliers least. g returns Hx - c + G'mu there. ok: a point was found
  !! with violation <= 1e-10 (relative).
  subroutine enumerate_box(h, c, gm, e, l, u, x, mu, g, ok)
    real(wp), intent(in) :: h(:, :), c(:), gm(:, :), e(:), l(:), u(:)
    real(wp), intent(out) :: x(:), mu(:), g(:)
    logical, intent(out) :: ok
    integer :: n, r, code, k, i, nf, info, state(size(c)), fr(size(c)), ipiv(size(c) + size(e))
    real(wp) :: kkt(size(c) + size(e), size(c) + size(e)), rhs(size(c) + size(e)), xt(size(c)), gt(size(c))
    real(wp) :: viol, best, xsc, gsc
    logical :: valid
    n = size(c)
    r = size(e)
    best = huge(1.0_wp)
    x = 0.0_wp
    mu = 0.0_wp
    g = 0.0_wp
    do code = 0, 3**n - 1
      k = code
      valid = .true.
      do i = 1, n
        state(i) = mod(k, 3)
        k = k / 3
        if (l(i) == u(i) .and. state(i) /= 1) valid = .false.
        if (state(i) == 1 .and. l(i) <= -huge(1.0_wp)) valid = .false.
        if (state(i) == 2 .and. (u(i) >= huge(1.0_wp) .or. l(i) == u(i))) valid = .false.
      end do
      if (.not. valid) cycle
      xt = 0.0_wp
      nf = 0
      do i = 1, n
        if (state(i) == 1) xt(i) = l(i)
        if (state(i) == 2) xt(i) = u(i)
        if (state(i) == 0) then
          nf = nf + 1
          fr(nf) = i
        end if
      end do
      if (nf < r) cycle
      kkt = 0.0_wp
      kkt(1:nf, 1:nf) = h(fr(1:nf), fr(1:nf))
      rhs(1:nf) = c(fr(1:nf)) - matmul(h(fr(1:nf), :), xt)
      if (r > 0) then
        kkt(1:nf, nf + 1:nf + r) = transpose(gm(:, fr(1:nf)))
        kkt(nf + 1:nf + r, 1:nf) = gm(:, fr(1:nf))
        rhs(nf + 1:nf + r) = e - matmul(gm, xt)
      end if
      if (nf + r > 0) then
        call dgesv(nf + r, 1, kkt, size(kkt, 1), ipiv, rhs, size(rhs), info)
        if (info /= 0) cycle
      end if
      xt(fr(1:nf)) = rhs(1:nf)
      gt = matmul(h, xt) - c
      if (r > 0) gt = gt + matmul(rhs(nf + 1:nf + r), gm)
      xsc = maxval(abs(xt)) + 1.0_wp
      gsc = maxval(abs(c)) + maxval(abs(h)) * xsc
      viol = 0.0_wp
      do i = 1, n
        select case (state(i))
        case (0)
          if (l(i) > -huge(1.0_wp)) viol = max(viol, (l(i) - xt(i)) / xsc)
          if (u(i) < huge(1.0_wp)) viol = max(viol, (xt(i) - u(i)) / xsc)
        case (1)
          if (l(i) < u(i)) viol = max(viol, -gt(i) / gsc)
        case (2)
          viol = max(viol, gt(i) / gsc)
        end select
      end do
      if (viol < best) then
        best = viol
        x = xt
        g = gt
        if (r > 0) mu = rhs(nf + 1:nf + r)
      end if
    end do
    ok = best <= 1.0e-10_wp
  end subroutine enumerate_box


  !> Projected gradient of g at x in the box, computed here (not by the solver's support).
  function box_projected(g, x, l, u) result(gp)
    real(wp), intent(in) :: g(:), x(:), l(:), u(:)
    real(wp) :: gp(size(g))
    integer :: i
    do i = 1, size(g)
      if (l(i) == u(i)) then
        gp(i) = 0.0_wp
      else if (x(i) <= l(i)) then
        gp(i) = min(g(i), 0.0_wp)
      else if (x(i) >= u(i)) then
        gp(i) = max(g(i), 0.0_wp)
      else
        gp(i) = g(i)
      end if
    end do
  end function box_projected

end module testing
