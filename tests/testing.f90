!> Helpers shared by the Fortran test programs: PASS/FAIL reporting with counters and
!! the closing line, the 1D obstacle problem of the MPRGP test and benchmark, and an independent direct solve of an assembled body
!! (LAPACK band Cholesky in the natural order) so the FE tests do not depend on the
!! Cholesky module that other tests check.
module testing
  use, intrinsic :: iso_fortran_env, only: output_unit
  use kinds, only: wp
  use assembly, only: body_system_t, expand
  use linop, only: csc_op_t, csc_op_init
  use lapack, only: dpbsv
  implicit none (type, external)
  private

  integer, public, protected :: npass = 0   !< checks passed so far
  integer, public, protected :: nfail = 0   !< checks failed so far

  public :: report, report_le, test_summary, band_solve, solve_full, obstacle_problem

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

end module testing
