!> What differs between a serial run (both bodies in this process, one OpenMP thread each,
!! CHOLMOD or banded Cholesky) and an MPI run (one group of ranks per body, MUMPS, rank 0
!! iterating): the phases the driver hands to a back-end, chosen once after the deck.
module run_backend
  use config, only: deck_t
  use run_state, only: run_t
  implicit none (type, external)
  private

  !> A back-end: memory check, factorization, condensation, the exchange of contact
  !! forces, the displacement recovery and the end of the run.
  type, abstract, public :: backend_t
    logical :: assembles_matrix = .true.   !< the assembly builds the stiffness (MUMPS: each rank its share later)
  contains
    procedure(check_memory_iface), deferred :: check_memory   !< refuse a deck that does not fit (exit 1)
    procedure(phase_iface), deferred :: factor                !< factorize both bodies
    procedure(phase_iface), deferred :: condense              !< both bodies' flexibilities F_a and b_a
    procedure(phase_iface), deferred :: condense_load         !< b_a alone, for a load step's loads (no factorization)
    procedure(phase_iface), deferred :: record_factor_memory  !< the factors' memory into the timing
    procedure(phase_iface), deferred :: share_contact_forces  !< rank 0's contact forces to every rank
    procedure(phase_iface), deferred :: recover               !< both bodies' displacements under their forces
    procedure(phase_iface), deferred :: agree_code            !< every rank takes rank 0's exit code
    procedure(phase_iface), deferred :: report_ranks          !< the ranks' memory line
    procedure(phase_iface), deferred :: finish                !< end the program with the run's code
  end type backend_t

  abstract interface
    subroutine check_memory_iface(self, run, the_deck)
      import :: backend_t, run_t, deck_t
      class(backend_t), intent(inout) :: self
      type(run_t), intent(in) :: run
      type(deck_t), intent(in) :: the_deck
    end subroutine check_memory_iface
    subroutine phase_iface(self, run)
      import :: backend_t, run_t
      class(backend_t), intent(inout) :: self
      type(run_t), intent(inout) :: run
    end subroutine phase_iface
  end interface

end module run_backend
