!> The data of one run, handed from phase to phase by the driver: the deck, every body
!! from its mesh to its condensed flexibility, the contact rows of all pairs, the contact
!! result, the displacements, the timing and the exit code. Also the rank's role in the
!! MPI binary: printing is rank 0's, and a fatal error ends every rank alike when all meet
!! it (collective phases) or aborts them all when one rank meets it alone.
module run_state
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use fatal_errors, only: fatal_handler, terminate
  use config, only: deck_t, output_cfg_t
  use deck, only: deck_text
  use mesh, only: mesh_t
  use assembly, only: body_system_t
  use contact_interface, only: interface_t
  use condense, only: body_condensed_t
  use contact_types, only: contact_result_t, robin_state_t
  use results, only: timing_t, step_result_t
  use load_history, only: load_step_t, step_history_t
  use strings, only: fixed
  use clock, only: wtime
  use mpi_env, only: par_built, par_init, par_finalize, par_rank, par_size, par_abort
  implicit none (type, external)
  private

  !> Everything one run computes, in the order the phases fill it.
  type, public :: run_t
    real(wp) :: t_start = 0.0_wp                       !< wall clock at the start [s]
    integer :: rank = 0                                !< this rank (0: the one that prints and writes)
    integer :: ranks = 1                               !< ranks of the run
    type(deck_t) :: deck                               !< the effective deck
    type(deck_t) :: sized                              !< the deck with mesh-file bodies sized by their node counts
    character(len=:), allocatable :: restart_file      !< checkpoint to restart from ('' none)
    character(len=:), allocatable :: key               !< the deck's physics, which a checkpoint must match
    character(len=:), allocatable :: mesh_ids          !< content hashes of the mesh files, which a checkpoint must match
    character(len=16), allocatable :: mesh_hex(:)      !< each body's mesh file's hash, of the bytes read ('' none)
    integer :: threads = 1                             !< OpenMP threads over the bodies
    integer :: nbody = 2                               !< bodies
    type(mesh_t), allocatable :: meshes(:)             !< the bodies' meshes
    type(body_system_t), allocatable :: systems(:)     !< their DOF maps, stiffnesses and loads
    type(interface_t) :: contact_line                  !< the contact rows of all pairs (mortar pairing)
    !> the rows' initial gaps of the geometry, kept while an interference fit is ramped over a
    !! stage (contact_line%g0 then holds the step's share of the overlap)
    real(wp), allocatable :: g0_full(:)
    type(body_condensed_t), allocatable :: bodies(:)   !< the bodies condensed on their contact rows
    type(robin_state_t) :: robin_state                 !< the Robin iteration's state (restart)
    type(contact_result_t) :: result                   !< contact forces, status, counts
    real(wp), allocatable :: displacement(:, :)        !< (max ndof, bodies) the bodies' displacements
    !> (max ndof, bodies) the supports' forces on each body (assembly's support_reactions, rank
    !! 0, once the displacements are complete) and (bodies) the size of the terms of K u they
    !! come from (their rounding level over eps)
    real(wp), allocatable :: reaction(:, :), reaction_mag(:)
    type(load_step_t), allocatable :: plan(:)          !< the load steps (one: the deck's loads at once)
    integer :: step = 1                                !< the step being solved
    integer :: restart_step = 1                        !< the step a checkpoint resumes (earlier ones are replayed)
    type(step_result_t), allocatable :: steps(:)       !< (steps solved) rank 0: each step's result, with several
    type(step_history_t) :: history                    !< what the last converged step hands the next
    type(timing_t) :: timing                           !< time per phase, memory
    logical :: written = .false.                       !< this run's result file exists
    integer :: code = 0                                !< the exit code
  end type run_t

  logical :: collective = .true.   ! a fatal error now is met by every rank alike
  integer :: my_rank = 0

  public :: start_ranks, set_collective, par_fatal, phase, physics_key

contains

  !> Start the parallel environment. In the MPI binary, the ranks other than 0 write their
  !! standard units to /dev/null and fatal errors take the ranks' route (par_fatal).
  subroutine start_ranks(run)
    type(run_t), intent(inout) :: run   !< the run: its start time, rank and ranks
    run%t_start = wtime()
    call par_init()
    if (.not. par_built) return
    run%rank = par_rank()
    run%ranks = par_size()
    run%timing%ranks = run%ranks
    my_rank = run%rank
    fatal_handler => par_fatal
    if (run%rank /= 0) then
      open (unit=output_unit, file='/dev/null', action='write')
      open (unit=error_unit, file='/dev/null', action='write')
    end if
  end subroutine start_ranks

  !> Whether a fatal error from now on is met by every rank alike (.true.) or possibly by
  !! this rank alone (.false.: rank 0's contact iteration and output; then MPI_Abort).
  subroutine set_collective(all_ranks)
    logical, intent(in) :: all_ranks   !< every rank meets the same errors
    collective = all_ranks
  end subroutine set_collective

  !> The MPI binary's fatal-error route: rank 0 prints the one message; when every rank
  !! meets the error alike (the deck, a status agreed by par_agree) they all finalize and
  !! exit with the code, otherwise (rank 0's output, its contact iteration) MPI_Abort ends
  !! them all with it.
  subroutine par_fatal(code, msg)
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    if (my_rank == 0) write (error_unit, '(a)') 'robin_contact: error: '//trim(msg)
    flush (error_unit)
    if (collective) then
      call par_finalize()
      call terminate(code)
    end if
    call par_abort(code)
  end subroutine par_fatal

  !> One line as each phase starts (flushed), so that a batch log shows where a run is.
  subroutine phase(run, what)
    type(run_t), intent(in) :: run        !< the run (its start time)
    character(len=*), intent(in) :: what  !< the phase
    write (output_unit, '(a)') 'phase: '//trim(what)//' (at '//fixed(wtime() - run%t_start, '(f0.1)')//' s)'
    flush (output_unit)
  end subroutine phase

  !> The effective deck without the settings that may change between a run and its
  !! restart (output, max_outer): a checkpoint is only accepted under the same key.
  function physics_key(the_deck) result(k)
    type(deck_t), intent(in) :: the_deck   !< the effective deck
    character(len=:), allocatable :: k
    type(deck_t) :: physics
    type(output_cfg_t) :: default_output
    physics = the_deck
    physics%output = default_output
    physics%source = ''
    physics%title = ''
    physics%solver%max_outer = 1
    call deck_text(physics, k)
  end function physics_key

end module run_state
