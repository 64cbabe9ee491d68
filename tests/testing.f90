!> Helpers shared by the Fortran test programs: PASS/FAIL reporting with counters and
!! the closing line, the 1D obstacle problem of the MPRGP test and benchmark, and an independent direct solve of an assembled body
!! (LAPACK band Cholesky in the natural order) so the FE tests do not depend on the
!! Cholesky module that other tests check, and a body on a general (unstructured-looking)
!! mesh for the ordering test and benchmark.
module testing
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use kinds, only: wp
  use config, only: body_cfg_t, traction_cfg_t, SIDE_TOP, SIDE_BOTTOM
  use mesh, only: mesh_t, mesh_build, side_nodes
  use elements, only: MAX_NVERT, MAX_NDOF, element_stiffness
  use assembly, only: body_system_t, expand, assemble_body, lame_parameters
  use linop, only: csc_op_t, csc_op_init
  use lapack, only: dpbsv
  implicit none (type, external)
  private

  integer, public, protected :: npass = 0   !< checks passed so far
  integer, public, protected :: nfail = 0   !< checks failed so far

  public :: report, report_le, test_summary, band_solve, solve_full, obstacle_problem, general_body

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
    integer :: j, k, info
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
    call csc_op_init(op, n, cp, ri, v, info)
    if (info /= 0) error stop 'csc_op_init failed'
    allocate (b(n), l(n))
    b = -15.0_wp
    l = -1.0_wp
  end subroutine obstacle_problem

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
    type(body_system_t) :: s0
    type(traction_cfg_t) :: tr(1)
    integer, allocatable :: new_of(:), ncell_of(:), cell_ptr(:), cell_list(:), mark(:), nbr(:), bottom(:)
    integer :: info, k, j, i, t, c, a, bb, node, nn, nd, cnt, p, q, kk, ldof(MAX_NDOF), pass
    integer(int64) :: state
    real(wp) :: hx, hy, lam, mu, xe(2, MAX_NVERT), ke(MAX_NDOF, MAX_NDOF), minjac
    character(len=256) :: msg

    tr(1)%body = b%id
    tr(1)%side = SIDE_TOP
    tr(1)%t0 = [1.0e6_wp, -3.0e6_wp]
    tr(1)%t1 = [0.0_wp, -1.0e6_wp]
    call mesh_build(grid, b, info, msg)
    if (info /= 0) error stop 'general_body: mesh_build failed'
    call assemble_body(grid, b, .true., tr, 1, s0, info, msg)
    if (info /= 0) error stop 'general_body: assemble_body failed'
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

    ! DOFs: prescribed as in the grid's system, free ones numbered in increasing order
    sys%id = b%id
    sys%ndof = 2*nn
    allocate (sys%free_of(sys%ndof))
    sys%free_of = 0
    do k = 1, nn
      do c = 1, 2
        if (s0%free_of(2*(k - 1) + c) > 0) sys%free_of(2*(new_of(k) - 1) + c) = 1
      end do
    end do
    sys%n = 0
    do k = 1, sys%ndof
      if (sys%free_of(k) > 0) then
        sys%n = sys%n + 1
        sys%free_of(k) = sys%n
      end if
    end do
    allocate (sys%dof_of(sys%n), sys%f(sys%n))
    do k = 1, sys%ndof
      if (sys%free_of(k) > 0) sys%dof_of(sys%free_of(k)) = k
    end do
    do p = 1, s0%n
      k = (s0%dof_of(p) + 1)/2
      c = s0%dof_of(p) - 2*(k - 1)
      sys%f(sys%free_of(2*(new_of(k) - 1) + c)) = s0%f(p)
    end do

    ! the cells of each node, then the pattern: the nodes sharing a cell, increasing
    allocate (ncell_of(nn + 1), mark(nn), nbr(0))
    ncell_of = 0
    do c = 1, msh%ncell
      do a = 1, msh%nvert
        ncell_of(msh%cells(a, c) + 1) = ncell_of(msh%cells(a, c) + 1) + 1
      end do
    end do
    cell_ptr = [0, (sum(ncell_of(2:k + 1)), k=1, nn)]
    allocate (cell_list(cell_ptr(nn + 1)))
    ncell_of = cell_ptr(1:nn + 1)
    do c = 1, msh%ncell
      do a = 1, msh%nvert
        node = msh%cells(a, c)
        ncell_of(node) = ncell_of(node) + 1
        cell_list(ncell_of(node)) = c
      end do
    end do
    allocate (sys%colptr(sys%n + 1))
    mark = 0
    do pass = 1, 2
      sys%colptr(1) = 0
      do p = 1, sys%n
        node = (sys%dof_of(p) + 1)/2
        if (mod(sys%dof_of(p), 2) == 0 .and. p > 1) then
          if ((sys%dof_of(p - 1) + 1)/2 == node) then     ! the y DOF: same rows as the x DOF
            cnt = sys%colptr(p) - sys%colptr(p - 1)
            if (pass == 2) sys%rowind(sys%colptr(p) + 1:sys%colptr(p) + cnt) = &
              sys%rowind(sys%colptr(p - 1) + 1:sys%colptr(p))
            sys%colptr(p + 1) = sys%colptr(p) + cnt
            cycle
          end if
        end if
        nbr = [integer ::]
        do kk = cell_ptr(node) + 1, cell_ptr(node + 1)
          do a = 1, msh%nvert
            q = msh%cells(a, cell_list(kk))
            if (mark(q) == p) cycle
            mark(q) = p
            nbr = [nbr, q]
          end do
        end do
        call isort(nbr)
        cnt = 0
        do kk = 1, size(nbr)
          do c = 1, 2
            q = sys%free_of(2*(nbr(kk) - 1) + c)
            if (q == 0) cycle
            cnt = cnt + 1
            if (pass == 2) sys%rowind(sys%colptr(p) + cnt) = q - 1
          end do
        end do
        sys%colptr(p + 1) = sys%colptr(p) + cnt
      end do
      if (pass == 1) allocate (sys%rowind(sys%colptr(sys%n + 1)))
      mark = 0
    end do

    ! the stiffness of the moved cells
    allocate (sys%val(size(sys%rowind)))
    sys%val = 0.0_wp
    call lame_parameters(b, .true., lam, mu)
    nd = 2*msh%nvert
    do c = 1, msh%ncell
      xe = 0.0_wp
      do a = 1, msh%nvert
        xe(:, a) = msh%xy(:, msh%cells(a, c))
        ldof(2*a - 1) = 2*(msh%cells(a, c) - 1) + 1
        ldof(2*a) = 2*(msh%cells(a, c) - 1) + 2
      end do
      call element_stiffness(msh%element, xe, lam, mu, ke, minjac)
      if (.not. minjac > 0.0_wp) error stop 'general_body: an inverted cell (perturb too large)'
      do bb = 1, nd
        p = sys%free_of(ldof(bb))
        if (p == 0) cycle
        do a = 1, nd
          q = sys%free_of(ldof(a))
          if (q == 0) cycle
          do kk = sys%colptr(p) + 1, sys%colptr(p + 1)
            if (sys%rowind(kk) == q - 1) exit
          end do
          if (kk > sys%colptr(p + 1)) error stop 'general_body: coupling outside the pattern'
          sys%val(kk) = sys%val(kk) + ke(a, bb)
        end do
      end do
    end do
    sys%k_norm = 0.0_wp
    do p = 1, sys%n
      sys%k_norm = max(sys%k_norm, sum(abs(sys%val(sys%colptr(p) + 1:sys%colptr(p + 1)))))
    end do

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

    subroutine isort(v)
      integer, intent(inout) :: v(:)
      integer :: i1, j1, t1
      do i1 = 2, size(v)
        t1 = v(i1)
        j1 = i1 - 1
        do while (j1 >= 1)
          if (v(j1) <= t1) exit
          v(j1 + 1) = v(j1)
          j1 = j1 - 1
        end do
        v(j1 + 1) = t1
      end do
    end subroutine isort

  end subroutine general_body

end module testing
