!> robin_contact: contact between elastic bodies, frictionless or with Tresca or Coulomb
!! friction (any number of bodies and contact pairs), by a Robin (Lions-type) nonoverlapping
!! domain decomposition (Sassi, Ipopa, Roux).
!!
!! Usage: robin_contact DECK.nml ['&group var=value ... /' ...]
!!        mpirun -np N robin_contact_mpi DECK.nml ... (factorization='mumps')
!! Exit codes: 0 converged, 1 bad input or usage, 2 did not converge,
!! 3 numerical failure, 4 interrupted (checkpoint written).
!! The same source is both binaries: module mpi_env (and mumps_iface) is compiled in its
!! serial or its MPI version by the Makefile. The phases below run in order; what differs
!! between a serial run and an MPI/MUMPS run (src/driver/serial_backend.f90,
!! mpi_backend.f90) is chosen once, after the deck.
program robin_contact
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit
  use errors, only: warn, error_t, ERR_INPUT
  use fatal_errors, only: fail_on
  use config, only: METHOD_ROBIN, program_version
  use deck, only: read_deck, print_deck
  use signals, only: signals_install
  use sysinfo, only: peak_rss_mb
  use budget, only: check_load_range
  use clock, only: wtime
  use strings, only: i2s
  use command_line, only: parse_arguments
  use run_state, only: run_t, start_ranks, set_collective, phase, physics_key
  use run_backend, only: backend_t
  use run_phases, only: choose_backend, choose_threads, read_meshes, assemble_bodies, build_contact_line, &
                        read_restart, factor_estimate, check_condensed, solve_steps, write_output, check_interrupt, &
                        check_output_names
  use run_summary, only: set_exit_code, summary, print_assembled
  implicit none (type, external)

  type(run_t) :: run
  class(backend_t), allocatable :: backend
  character(len=:), allocatable :: deck_path
  character(len=4096), allocatable :: overrides(:)
  real(wp) :: t0
  type(error_t) :: err

  ! ---- the deck, and a deck that cannot fit this machine refused before anything is allocated
  call start_ranks(run)
  call parse_arguments(run%rank, deck_path, overrides, run%restart_file)
  call read_deck(deck_path, overrides, run%deck, err)
  call fail_on(err)   ! read_deck's messages name their source (the deck and line, or the override)
  call choose_backend(run, backend)
  if (len(run%restart_file) > 0 .and. run%deck%solver%method /= METHOD_ROBIN) &
    call fail_on(error_t(ERR_INPUT, '--restart applies to method=''robin'' only'), 'deck '//trim(run%deck%source))
  if (.not. signals_install()) call warn('cannot install the SIGTERM/SIGINT handlers')
  call backend%check_memory(run, run%deck)
  call check_load_range(run%deck, err)
  call fail_on(err, 'deck '//trim(run%deck%source))
  call check_output_names(run)
  run%key = physics_key(run%deck)
  write (output_unit, '(a)') 'robin_contact '//program_version//': effective input'
  call print_deck(run%deck, output_unit)
  call choose_threads(run)

  ! ---- assemble the bodies, the contact rows of all pairs ------------------------------
  call phase(run, merge('assembly of both bodies', 'assembly of the bodies ', run%deck%nbody == 2))
  t0 = wtime()
  call read_meshes(run, backend)
  call assemble_bodies(run, matrix=backend%assembles_matrix)
  call build_contact_line(run)
  call read_restart(run)
  run%timing%assemble = wtime() - t0
  call check_interrupt(run, backend, 'assembly')
  call print_assembled(run)

  ! ---- factorize and condense on the contact line -------------------------------------
  if (run%nbody == 2) then
    call phase(run, 'ordering and factorization (estimated factors: body 1 '//factor_estimate(run, 1)// &
               ', body 2 '//factor_estimate(run, 2)//')')
  else
    call phase(run, 'ordering and factorization ('//i2s(run%nbody)//' bodies, estimated factors '// &
               factor_estimate(run)//' in all)')
  end if
  t0 = wtime()
  call backend%factor(run)
  run%timing%factor = wtime() - t0
  call check_interrupt(run, backend, 'factorization')
  t0 = wtime()
  call backend%condense(run)
  call check_condensed(run)
  run%timing%condense = wtime() - t0
  call check_interrupt(run, backend, 'condensation')
  call backend%record_factor_memory(run)

  ! ---- contact forces (rank 0 alone), then the bodies' displacements, step by step ---------
  call phase(run, merge('Robin iteration  ', 'monolithic solve ', run%deck%solver%method == METHOD_ROBIN))
  t0 = wtime()
  call solve_steps(run, backend)
  run%timing%iterate = wtime() - t0
  call set_exit_code(run)

  ! ---- the result file, the summary, the exit code --------------------------------------
  call phase(run, 'output')
  t0 = wtime()
  call set_collective(.false.)
  call write_output(run)
  call set_collective(.true.)
  call backend%agree_code(run)
  run%timing%output = wtime() - t0
  run%timing%total = wtime() - run%t_start
  run%timing%peak_rss_mb = peak_rss_mb()
  call backend%report_ranks(run)
  call summary(run)
  call backend%finish(run)

end program robin_contact
