!> Helpers shared by the finite-element tests: an independent direct solve of an
!! assembled body (LAPACK band Cholesky in the natural order), so that the FE tests do
!! not depend on the Cholesky module under test elsewhere.
module fe_testing
  use kinds, only: wp
  use assembly, only: body_system_t
  implicit none
  private
  public :: band_solve

contains

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

end module fe_testing
