!> The serial binary's stand-in for module mumps_iface (mumps_iface.f90, MPI build only):
!! the same API, and every call is an error, so the code that uses it compiles in both
!! binaries. The driver refuses factorization='mumps' before any call reaches here.
module mumps_iface
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  logical, parameter, public :: mumps_built = .false.   !< this binary has no MUMPS

  !> Placeholder of one factorized body.
  type, public :: mumps_t
    logical :: host = .true.                  !< this rank is the group's host
    integer :: n = 0                          !< unknowns
    integer :: k = 0                          !< Schur (interface) variables
    real(wp), allocatable :: x(:, :)          !< (k,k) S^-1 (never set here)
    real(wp) :: mem_bytes = 0.0_wp            !< factor memory [byte]
    real(wp) :: max_rank_mb = 0.0_wp          !< the largest rank's factorization memory [MiB]
    real(wp) :: factor_mb = 0.0_wp            !< the factor's entries over the group [MiB]
    real(wp) :: rank_factor_mb = 0.0_wp       !< this rank's share of them [MiB]
  end type mumps_t

  public :: mumps_schur_factor, mumps_solve, mumps_end

  character(len=*), parameter :: NONE = 'this binary is built without MUMPS: run bin/robin_contact_mpi under mpirun'

contains

  !> Not available: ERR_INPUT (the deck asks for what this binary lacks).
  subroutine mumps_schur_factor(mt, comm, n, irn, jcn, val, schur, body, err)
    type(mumps_t), intent(inout) :: mt
    integer, intent(in) :: comm, n, irn(:), jcn(:), schur(:), body
    real(wp), intent(in) :: val(:)
    type(error_t), intent(out) :: err
    mt%n = n + 0*(comm + body + size(irn) + size(jcn) + size(val) + size(schur))
    call err%set(ERR_INPUT, NONE)
  end subroutine mumps_schur_factor

  !> Not available: ERR_INPUT (the deck asks for what this binary lacks).
  subroutine mumps_solve(mt, r, body, err)
    type(mumps_t), intent(inout) :: mt
    real(wp), intent(inout) :: r(:)
    integer, intent(in) :: body
    type(error_t), intent(out) :: err
    mt%k = mt%k + 0*(size(r) + body)
    call err%set(ERR_INPUT, NONE)
  end subroutine mumps_solve

  !> Nothing to free.
  subroutine mumps_end(mt)
    type(mumps_t), intent(inout) :: mt
    mt%k = 0
  end subroutine mumps_end

end module mumps_iface
