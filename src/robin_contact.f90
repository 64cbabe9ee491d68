!> robin_contact: frictionless contact between two elastic bodies by a Robin
!! (Lions-type) nonoverlapping domain decomposition (Sassi, Ipopa, Roux).
!!
!! Usage: robin_contact DECK.nml ['&group var=value ... /' ...]
!!        mpirun -np N robin_contact_mpi DECK.nml ... (factorization='mumps')
!! Exit codes: 0 converged, 1 bad input or usage, 2 did not converge,
!! 3 numerical failure, 4 interrupted (checkpoint written).
!! The same source is both binaries: module mpi_env (and mumps_iface) is compiled in its
!! serial or its MPI version by the Makefile. In the MPI binary every rank reads the deck,
!! meshes and numbers both bodies and integrates their loads; each body's group of ranks
!! computes its share of the body's element matrices and factorizes it by MUMPS; rank 0
!! alone runs the contact iteration, prints and writes; every rank ends with the same code.
program robin_contact
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use errors, only: fatal, fatal_handler, terminate, warn, EXIT_OK, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_NUMERICAL, &
                    EXIT_INTERRUPTED
  use config, only: deck_t, output_cfg_t, solver_cfg_t, ROBIN_HARMONIC, METHOD_ROBIN, METHOD_MONOLITHIC, FACTOR_MUMPS, &
                    FACTOR_CHOICES
  use deck, only: read_deck, print_deck, deck_usage, deck_text, deck_reference
  use mesh, only: mesh_t, mesh_build
  use gmsh_msh, only: msh_read, msh_read_pair
  use assembly, only: body_system_t, assemble_body, expand, cell_triplets
  use condense, only: interface_t, body_condensed_t, build_interface, factor_body, condense_body, contact_resultant, &
                      recover_displacement
  use contact_types, only: contact_result_t, robin_state_t, status_name, STATUS_CONVERGED, STATUS_FAILED, &
                           STATUS_INTERRUPTED
  use robin_iteration, only: solve_robin
  use monolithic, only: solve_monolithic
  use error_estimate, only: error_bound
  use floating, only: rigid_rows, check_held, free_list, fixing_list
  use results, only: timing_t, write_results, program_version
  use checkpoint, only: h5_checkpointer_t, checkpoint_read, checkpoint_file
  use files, only: remove_file
  use signals, only: signals_install, stop_requested, pending_signal
  use sysinfo, only: peak_rss_mb, memory_limit_mb, node_memory_limit_mb, process_memory_limit_mb, write_stdout_checked
  use budget, only: check_budget, check_load_range, body_memory_mb, rank_memory_mb, check_budget_ranks
  use strings, only: sci, fmt_real, i2s, word
  use omp_lib, only: omp_get_max_threads, omp_set_max_active_levels
  use clock, only: wtime
  use mpi_env, only: par_built, par_init, par_finalize, par_rank, par_size, par_split, par_bcast_reals, &
                     par_bcast_ints, par_agree, par_any, par_abort, par_max_real, par_sum_real, par_node_sum
  use mumps_iface, only: mumps_t, mumps_end
  use condense_mumps, only: factor_body_mumps, condense_body_mumps, recover_displacement_mumps
  implicit none (type, external)

  type(deck_t) :: d
  type(mesh_t) :: msh(2)
  type(deck_t) :: dsized
  type(body_system_t) :: sys(2)
  type(interface_t) :: itf
  type(body_condensed_t) :: cb(2)   ! the bodies condensed on the interface
  type(contact_result_t) :: res
  type(timing_t) :: tm
  character(len=:), allocatable :: deck_path, restart_file, key, budget_msg
  character(len=4096), allocatable :: overrides(:)
  type(robin_state_t) :: state
  type(h5_checkpointer_t) :: ckpt
  character(len=512) :: msg(2), msg1
  integer :: info(2), info1, a, nthr, code, maxndof
  real(wp) :: t_start, t0
  real(wp), allocatable :: u(:, :), ufree(:)
  logical :: ok
  logical :: written = .false.   ! the result file of this run exists
  ! MPI binary: this rank, the world's size, whether this run factorizes by MUMPS, the world
  ! rank hosting each body's group, this rank's group, and whether a fatal error now is met
  ! by every rank alike (deck, collective checks) or by this rank alone (then MPI_Abort)
  integer :: me = 0, nranks = 1, host(2) = 0, gcomm = 0, grank(2) = 0, gsize(2) = 1
  integer, allocatable :: irn(:), jcn(:)   ! this rank's share of a stiffness (MUMPS input)
  real(wp), allocatable :: kval(:)
  logical :: use_mumps = .false., mine(2) = .true., collective = .true.
  real(wp) :: assembly_peak_mb = 0.0_wp   ! this rank's peak RSS when the factorization starts [MiB]
  type(mumps_t) :: mt(2)

  t_start = wtime()
  call par_init()
  if (par_built) then
    me = par_rank()
    nranks = par_size()
    tm%ranks = nranks
    fatal_handler => par_fatal
    ! printing is rank 0's: the others write their standard units to /dev/null
    if (me /= 0) then
      open (unit=output_unit, file='/dev/null', action='write')
      open (unit=error_unit, file='/dev/null', action='write')
    end if
  end if
  call parse_arguments(deck_path, overrides, restart_file)
  call read_deck(deck_path, overrides, d)
  use_mumps = d%solver%factor%factorization == FACTOR_MUMPS
  if (use_mumps .and. .not. par_built) call fatal(EXIT_INPUT, 'deck '//trim(d%source)// &
    ': factorization=''mumps'' needs the MPI binary: run mpirun -np N bin/robin_contact_mpi '// &
    trim(d%source)//' (built by make MPI=1); this binary has no MPI or MUMPS')
  if (.not. use_mumps .and. nranks > 1) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': factorization='''// &
    word(FACTOR_CHOICES, d%solver%factor%factorization)//''' runs on one rank, and this run has '//i2s(nranks)// &
    '; use factorization=''mumps'' or mpirun -np 1')
  if (len(restart_file) > 0 .and. d%solver%method /= METHOD_ROBIN) &
    call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': --restart applies to method=''robin'' only')
  if (.not. signals_install()) call warn('cannot install the SIGTERM/SIGINT handlers')
  ! a deck that cannot fit this machine is refused before anything is allocated
  call check_memory(d)
  call check_load_range(d, ok, budget_msg)
  if (.not. ok) call fatal(EXIT_INPUT, budget_msg)
  key = physics_key(d)
  write (output_unit, '(a)') 'robin_contact '//program_version//': effective input'
  call print_deck(d, output_unit)
  nthr = max(1, min(2, omp_get_max_threads()))
  ! Parallelism is over the two bodies. CHOLMOD opens OpenMP regions of its own with a
  ! fixed num_threads(4); inside our 2-thread region they are nested and run serially, but
  ! with one thread our region is inactive and CHOLMOD's would start 4 threads on the
  ! cores we use (measured: 10x slower factorization). So no region below ours is active.
  if (nthr == 1) then
    call omp_set_max_active_levels(0)
  else
    call omp_set_max_active_levels(1)
  end if

  ! An earlier result at this path stays until this run's result replaces it whole
  ! (write_results); a run that fails leaves it untouched.

  ! ---- assemble both bodies --------------------------------------------------------
  call phase('assembly of both bodies')
  t0 = wtime()
  if (len_trim(d%body(1)%mesh) > 0 .and. d%body(1)%mesh == d%body(2)%mesh) then
    ! one file holds both bodies: read and parse it once
    call msh_read_pair(trim(d%body(1)%mesh), [d%body(1)%region, d%body(2)%region], msh, info, msg, nthr)
  else
    !$omp parallel do num_threads(nthr) schedule(static, 1)
    do a = 1, 2
      if (len_trim(d%body(a)%mesh) > 0) then
        call msh_read(trim(d%body(a)%mesh), trim(d%body(a)%region), a, msh(a), info(a), msg(a))
      else
        call mesh_build(msh(a), d%body(a))
        info(a) = 0
      end if
    end do
    !$omp end parallel do
  end if
  do a = 1, 2   ! the mesh reader's message names the body
    if (info(a) == 1) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': '//trim(msg(a)))
    if (info(a) /= 0) call fatal(EXIT_NUMERICAL, 'deck '//trim(d%source)//': '//trim(msg(a)))
  end do
  ! a body from a mesh file is sized now: the memory check again, with its node count
  dsized = d
  if (len_trim(d%body(1)%mesh) > 0 .or. len_trim(d%body(2)%mesh) > 0) then
    do a = 1, 2
      if (len_trim(d%body(a)%mesh) == 0) cycle
      dsized%body(a)%nx = max(1, nint(sqrt(real(msh(a)%nnode, wp))) - 1)
      dsized%body(a)%ny = max(1, msh(a)%nnode/(dsized%body(a)%nx + 1) - 1)
    end do
    call check_memory(dsized)
  end if
  !$omp parallel do num_threads(nthr) schedule(static, 1)
  do a = 1, 2
    ! MUMPS: the DOF numbering and the load only; each rank assembles its cells' share later
    call assemble_body(msh(a), d%body(a), d%plane_strain, d%traction, d%ntraction, sys(a), info(a), msg(a), &
                       boundaries=d%boundary(1:d%nboundary), matrix=.not. use_mumps, &
                       contact_group=d%contact%body_group(a))
  end do
  !$omp end parallel do
  do a = 1, 2
    if (info(a) /= 0) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//', body '//achar(48 + a)//': '//trim(msg(a)))
  end do
  call build_interface(d%body, d%contact, msh, sys, itf, info1, msg1)
  if (info1 /= 0) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': '//trim(msg1))
  ! a body held only by contact: its equilibrium rows, and whether the contact can hold it
  do a = 1, 2
    call rigid_rows(itf, a, sys(a), cb(a))
  end do
  if (sys(1)%nrig + sys(2)%nrig > 0) then
    call check_held(sys, cb, info1, msg1)
    if (info1 /= 0) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': '//trim(msg1))
    do a = 1, 2
      if (sys(a)%nrig > 0) write (output_unit, '(a)') 'floating: body '//achar(48 + a)//' is held only by '// &
        'contact (free: '//free_list(sys(a))//'); fixing DOFs for its generalized inverse: '//fixing_list(sys(a))// &
        '; kernel check |K R|/(|K| |R|) = '//sci(sys(a)%rig_residual)
    end do
  end if
  ! the checkpoint to restart from is input too: read and check it before touching any file
  if (len(restart_file) > 0) then
    call checkpoint_read(restart_file, key, itf%m, d%solver%max_outer, state, res, ok, msg1)
    if (.not. ok) call fatal(EXIT_INPUT, trim(msg1))
  end if
  tm%assemble = wtime() - t0
  call check_interrupt('assembly')
  write (output_unit, '(a,i0,a,i0,a,i0,a,i0)') 'assembled: n1=', sys(1)%n, ' n2=', sys(2)%n, &
    ' m=', itf%m, ' threads=', nthr

  ! ---- factorize and condense (one thread per body) -------------------------------
  call phase('ordering and factorization (estimated factors: body 1 '//factor_estimate(1)//', body 2 '// &
             factor_estimate(2)//')')
  t0 = wtime()
  if (use_mumps) then
    call mumps_groups()
    do a = 1, 2
      info(a) = 0
      msg(a) = ''
      if (.not. mine(a)) cycle
      ! this rank's share of body a's cells (rank r of g: cells r*nc/g+1 .. (r+1)*nc/g)
      call cell_triplets(msh(a), d%body(a), d%plane_strain, sys(a), grank(a)*msh(a)%ncell/gsize(a) + 1, &
                         (grank(a) + 1)*msh(a)%ncell/gsize(a), irn, jcn, kval, info(a), msg(a))
      if (info(a) == 0) call factor_body_mumps(itf, a, sys(a), irn, jcn, kval, gcomm, cb(a), mt(a), info(a), msg(a))
      if (allocated(irn)) deallocate (irn, jcn, kval)
    end do
    call agree_fatal('factorization failed')
  else
    !$omp parallel do num_threads(nthr) schedule(static, 1)
    do a = 1, 2
      call factor_body(d%solver%factor, itf, a, msh(a), sys(a), cb(a), info(a), msg(a))
    end do
    !$omp end parallel do
    do a = 1, 2
      if (info(a) /= 0) call fatal(EXIT_NUMERICAL, 'body '//achar(48 + a)//': factorization failed: '//trim(msg(a)))
    end do
  end if
  tm%factor = wtime() - t0
  call check_interrupt('factorization')
  t0 = wtime()
  if (use_mumps) then
    do a = 1, 2
      if (mine(a)) call condense_body_mumps(sys(a), cb(a), mt(a), a, info(a), msg(a))
    end do
    call agree_fatal('condensation failed')
    call share_condensed()
  else
    !$omp parallel do num_threads(nthr) schedule(static, 1)
    do a = 1, 2
      call condense_body(sys(a), cb(a), info(a), msg(a))
    end do
    !$omp end parallel do
  end if
  do a = 1, 2
    if (info(a) /= 0) call fatal(EXIT_NUMERICAL, 'body '//achar(48 + a)//': condensation failed: '//trim(msg(a)))
    if (.not. (all(ieee_is_finite(cb(a)%flex)) .and. all(ieee_is_finite(cb(a)%b)))) then
      write (msg1, '(a,i0,a,es10.3,a)') 'body ', a, ': its interface flexibility is not finite (young = ', &
        d%body(a)%young, '): the stiffness is out of the range of double precision; rescale the units'
      call fatal(EXIT_NUMERICAL, trim(msg1))
    end if
  end do
  tm%condense = wtime() - t0
  call check_interrupt('condensation')
  if (use_mumps) then
    tm%factor_mb = (mt(1)%mem_bytes + mt(2)%mem_bytes)/1048576.0_wp
  else
    tm%factor_mb = (cb(1)%chol%mem_bytes + cb(2)%chol%mem_bytes)/1048576.0_wp
  end if

  ! ---- contact ----------------------------------------------------------------------
  call phase(merge('Robin iteration  ', 'monolithic solve ', d%solver%method == METHOD_ROBIN))
  t0 = wtime()
  collective = .false.
  if (me /= 0) then
    ! the contact iteration is rank 0's; the others wait for its contact forces
  else if (d%solver%method == METHOD_MONOLITHIC) then
    call solve_monolithic(d%solver, itf, cb, res, stop_requested)
  else
    ckpt%file = checkpoint_file(d%output%file)
    ckpt%key = key
    ckpt%every = d%output%checkpoint_every
    call solve_robin(d%solver, itf, cb, res, output_unit, d%output%progress_lines, state, ckpt, stop_requested)
    if (ckpt%failed) call warn(ckpt%message)
  end if
  if (me == 0 .and. res%status /= STATUS_FAILED) call error_bound(itf, cb, res)
  if (me == 0 .and. res%status /= STATUS_FAILED .and. itf%m > 0) then
    ! a floating body's load against its contact force: the equality the solver enforced
    do a = 1, 2
      if (sys(a)%nrig == 0) cycle
      write (output_unit, '(a)') 'equilibrium: body '//achar(48 + a)//' |G lam - e|/|e| = '// &
        sci(norm2(matmul(cb(a)%rg, res%lam_body(:, a)) - cb(a)%re)/norm2(cb(a)%re))//' (its own force), '// &
        sci(norm2(matmul(cb(a)%rg, res%lam) - cb(a)%re)/norm2(cb(a)%re))//' (mean force); rigid motion '// &
        'amplitudes '//trim(amplitudes(a))//'; SMALBE multiplier updates (this run''s solves) '//i2s(res%eq_updates)
    end do
  end if
  collective = .true.
  if (use_mumps) call share_contact_forces()
  ! displacements of both bodies under their own contact forces
  maxndof = max(sys(1)%ndof, sys(2)%ndof)
  allocate (u(maxndof, 2))
  u = 0.0_wp
  if (use_mumps .and. res%status /= STATUS_FAILED) then
    call recover_mumps()
  else if (res%status /= STATUS_FAILED) then
    !$omp parallel do num_threads(nthr) schedule(static, 1) private(ufree)
    do a = 1, 2
      allocate (ufree(sys(a)%n))
      call recover_displacement(sys(a), cb(a), res%lam_body(:, a), ufree)
      call expand(sys(a), ufree, u(1:sys(a)%ndof, a))
      deallocate (ufree)
    end do
    !$omp end parallel do
  end if
  ! a floating body's rigid part: u_a = K_a^+ (f_a - B_a' lam) + R_a alpha_a (rank 0 writes)
  if (res%status /= STATUS_FAILED .and. me == 0) then
    do a = 1, 2
      if (sys(a)%nrig > 0) u(1:sys(a)%ndof, a) = u(1:sys(a)%ndof, a) + matmul(sys(a)%rig, res%rigid(1:sys(a)%nrig, a))
    end do
  end if
  if (res%status /= STATUS_FAILED .and. .not. all(ieee_is_finite(u))) then
    ! a derived field that is not finite is a failure, never a result
    res%status = STATUS_FAILED
    res%message = 'the displacements are not finite: the problem is beyond double precision; rescale the units'
  end if
  tm%iterate = wtime() - t0

  select case (res%status)
  case (STATUS_CONVERGED)
    code = EXIT_OK
  case (STATUS_FAILED)
    code = EXIT_NUMERICAL
  case (STATUS_INTERRUPTED)
    code = EXIT_INTERRUPTED
  case default
    code = EXIT_NOT_CONVERGED
  end select
  if (res%status /= STATUS_CONVERGED) write (error_unit, '(a)') 'robin_contact: '//status_name(res%status)//': '//trim(res%message)
  if (code == EXIT_NOT_CONVERGED) write (error_unit, '(a)') 'robin_contact: next: '//next_setting(d%solver)

  ! ---- output -------------------------------------------------------------------------
  call phase('output')
  t0 = wtime()
  collective = .false.
  if (code /= EXIT_NUMERICAL .and. me == 0) then
    tm%peak_rss_mb = peak_rss_mb()
    tm%total = wtime() - t_start
    call write_results(d%output%file, d, msh, sys, itf, res, u, tm, ok, msg1)
    written = ok
    if (.not. ok) call fatal(EXIT_NUMERICAL, 'output: '//trim(msg1))
    ! a converged run has no use for its checkpoint; a run that stopped keeps it
    if (code == EXIT_OK) call remove_file(checkpoint_file(d%output%file))
  end if
  collective = .true.
  if (use_mumps) then
    ! rank 0 decides the exit code (the output may have failed there)
    info(1) = code
    call par_bcast_ints(info, 1, 0)
    code = info(1)
  end if
  tm%output = wtime() - t0
  tm%total = wtime() - t_start
  tm%peak_rss_mb = peak_rss_mb()
  if (use_mumps) call report_rank_peaks()
  call summary()
  call finish(code)

contains

  !> Body a's rigid motion amplitudes (the displacement of its fixing DOFs), space-separated.
  function amplitudes(a) result(t)
    integer, intent(in) :: a
    character(len=64) :: t
    integer :: k
    t = ''
    do k = 1, sys(a)%nrig
      t = trim(t)//' '//sci(res%rigid(k, a))
    end do
    t = adjustl(t)
  end function amplitudes

  !> End the run with code on every rank (MPI binary: MUMPS instances freed, MPI finalized).
  subroutine finish(code)
    integer, intent(in) :: code
    integer :: b
    if (use_mumps) then
      do b = 1, 2
        if (mine(b)) call mumps_end(mt(b))
      end do
    end if
    call par_finalize()
    call terminate(code)
  end subroutine finish

  !> The MPI binary's fatal-error route: rank 0 prints the one message; when every rank
  !! meets the error alike (the deck, a status agreed by par_agree) they all finalize and
  !! exit with the code, otherwise (rank 0's output, its contact iteration) MPI_Abort ends
  !! them all with it.
  subroutine par_fatal(code, msg)
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    if (me == 0) write (error_unit, '(a)') 'robin_contact: error: '//trim(msg)
    flush (error_unit)
    if (collective) then
      call par_finalize()
      call terminate(code)
    end if
    call par_abort(code)
  end subroutine par_fatal

  !> Refuse a deck that does not fit (exit 1, nothing allocated yet). One process: the
  !! whole run against this process's memory. MUMPS on ranks: each rank's estimate (its
  !! share of its body's factor, the meshes of both bodies) against ulimit -v, and the sum
  !! over the ranks of each node against the node's memory; every rank agrees (collective).
  subroutine check_memory(dd)
    type(deck_t), intent(in) :: dd
    real(wp) :: est, node_est
    integer :: st, node_ranks
    character(len=1024) :: m1
    if (.not. use_mumps) then
      call check_budget(dd, memory_limit_mb(), ok, budget_msg)
      if (.not. ok) call fatal(EXIT_INPUT, budget_msg)
      return
    end if
    est = rank_memory_mb(dd, nranks, me)
    call par_node_sum(est, node_est, node_ranks)
    call check_budget_ranks(dd, nranks, me, est, node_est, node_ranks, node_memory_limit_mb(), &
                            process_memory_limit_mb(), ok, budget_msg)
    st = merge(0, EXIT_INPUT, ok)
    m1 = budget_msg
    call par_agree(st, m1)
    if (st /= 0) call fatal(EXIT_INPUT, trim(m1))
  end subroutine check_memory

  !> Split the ranks into one group per body (MPI_Comm_split): one rank does both bodies
  !! in turn; otherwise half each, an odd one out to the body with more unknowns. The
  !! lower world ranks form body 1's group, so world rank 0 hosts body 1.
  subroutine mumps_groups()
    integer :: g1, b
    assembly_peak_mb = peak_rss_mb()   ! meshes, numbering and loads of both bodies
    if (nranks == 1) then
      mine = .true.
      host = 0
      call par_split(0, gcomm)
      return
    end if
    g1 = nranks/2
    if (mod(nranks, 2) == 1 .and. sys(1)%n >= sys(2)%n) g1 = g1 + 1
    host = [0, g1]
    mine = [me < g1, me >= g1]
    gsize = [g1, nranks - g1]
    grank = [me, me - g1]
    do b = 1, 2
      if (merge(g1, nranks - g1, b == 1) > msh(b)%ncell) call fatal(EXIT_INPUT, 'deck '//trim(d%source)// &
        ': '//i2s(merge(g1, nranks - g1, b == 1))//' ranks for body '//achar(48 + b)//', which has '// &
        i2s(msh(b)%ncell)//' cells: use at most '//i2s(2*min(msh(1)%ncell, msh(2)%ncell))//' ranks')
    end do
    call par_split(merge(1, 2, me < g1), gcomm)
    write (output_unit, '(a,i0,a,i0,a)') 'mumps: ', g1, ' rank(s) on body 1, ', nranks - g1, ' on body 2'
  end subroutine mumps_groups

  !> One line with the largest peak resident memory (VmHWM, getrusage) of any rank, which
  !! rank, and the sum over the ranks (what the job needs on one node); the largest peak
  !! at the start of the factorization tells the meshes' and loads' share. Collective.
  subroutine report_rank_peaks()
    real(wp) :: pmax, psum, amax
    integer :: where, awhere
    call par_max_real(peak_rss_mb(), pmax, where)
    psum = par_sum_real(peak_rss_mb())
    call par_max_real(assembly_peak_mb, amax, awhere)
    write (output_unit, '(a,i0,a,f0.1,a,i0,a,f0.1,a,f0.1)') 'mpi: ranks=', nranks, ' peak_rss_max_rank_mb=', pmax, &
      ' max_rank=', where, ' peak_rss_sum_mb=', psum, ' assembly_peak_max_rank_mb=', amax
    flush (output_unit)
  end subroutine report_rank_peaks

  !> Every rank learns the worst status of the bodies' groups; a failure is fatal (exit 3)
  !! on all ranks with the message of the lowest failing rank.
  subroutine agree_fatal(what)
    character(len=*), intent(in) :: what
    integer :: st, b
    character(len=512) :: m1
    st = 0
    m1 = ''
    do b = 2, 1, -1
      if (info(b) /= 0) then
        st = EXIT_NUMERICAL
        m1 = 'body '//achar(48 + b)//': '//what//': '//trim(msg(b))
      end if
    end do
    call par_agree(st, m1)
    if (st /= 0) call fatal(st, trim(m1))
  end subroutine agree_fatal

  !> Each group's host sends its body's F_a, b_a and the proximal weight to every rank.
  subroutine share_condensed()
    integer :: b, iv(1)
    real(wp) :: rv(3)
    do b = 1, 2
      if (.not. (mine(b) .and. mt(b)%host)) then
        if (allocated(cb(b)%flex)) deallocate (cb(b)%flex)
        allocate (cb(b)%flex(itf%m, itf%m))
        cb(b)%m = itf%m
      end if
      if (.not. allocated(cb(b)%b)) allocate (cb(b)%b(itf%m))
      call par_bcast_reals(cb(b)%flex, itf%m*itf%m, host(b))
      call par_bcast_reals(cb(b)%b, itf%m, host(b))
      rv = [cb(b)%prox, mt(b)%mem_bytes, mt(b)%max_rank_mb]
      call par_bcast_reals(rv, 3, host(b))
      cb(b)%prox = rv(1)
      mt(b)%mem_bytes = rv(2)
      mt(b)%max_rank_mb = rv(3)
      iv(1) = cb(b)%rank
      call par_bcast_ints(iv, 1, host(b))
      cb(b)%rank = iv(1)
      ! the kernel basis of a singular F_a (flex_rank; -1: none), which the harmonic
      ! operator's proximal term needs on rank 0 as much as on the body's host
      iv(1) = -1
      if (allocated(cb(b)%kern)) iv(1) = size(cb(b)%kern, 2)
      call par_bcast_ints(iv, 1, host(b))
      if (iv(1) >= 0) then
        if (.not. (mine(b) .and. mt(b)%host)) then
          if (allocated(cb(b)%kern)) deallocate (cb(b)%kern)
          allocate (cb(b)%kern(itf%m, iv(1)))
        end if
        if (iv(1) > 0) call par_bcast_reals(cb(b)%kern, itf%m*iv(1), host(b))
      end if
      info(b) = 0
    end do
    write (output_unit, '(a,2(f0.1,a))') 'mumps: largest rank''s factorization memory: body 1 ', &
      mt(1)%max_rank_mb, ' MB, body 2 ', mt(2)%max_rank_mb, ' MB'
  end subroutine share_condensed

  !> Rank 0's contact forces and status to every rank (the others need lam to recover their
  !! body's displacement, and the status to end alike).
  subroutine share_contact_forces()
    integer :: iv(1)
    iv(1) = res%status
    call par_bcast_ints(iv, 1, 0)
    if (me /= 0) then
      res%status = iv(1)
      if (allocated(res%lam_body)) deallocate (res%lam_body)
      allocate (res%lam_body(itf%m, 2))
    end if
    if (iv(1) /= STATUS_FAILED) call par_bcast_reals(res%lam_body, 2*itf%m, 0)
  end subroutine share_contact_forces

  !> Each group solves its body under its contact forces; the hosts send the displacements
  !! to rank 0 (broadcast: every rank receives them in this first version).
  subroutine recover_mumps()
    integer :: b
    real(wp), allocatable :: uf(:)
    do b = 1, 2
      info(b) = 0
      msg(b) = ''
      if (.not. mine(b)) cycle
      allocate (uf(sys(b)%n))
      uf = 0.0_wp
      call recover_displacement_mumps(sys(b), cb(b), mt(b), b, res%lam_body(:, b), uf, info(b), msg(b))
      if (mt(b)%host) call expand(sys(b), uf, u(1:sys(b)%ndof, b))
      deallocate (uf)
    end do
    call agree_fatal('displacement recovery failed')
    do b = 1, 2
      if (host(b) /= 0) call par_bcast_reals(u(1, b), sys(b)%ndof, host(b))
    end do
  end subroutine recover_mumps

  !> One line as each phase starts (flushed), so that a batch log shows where a run is.
  subroutine phase(what)
    character(len=*), intent(in) :: what
    write (output_unit, '(a)') 'phase: '//trim(what)//' (at '//fmt_real(wtime() - t_start, '(f0.1)')//' s)'
    flush (output_unit)
  end subroutine phase

  !> The budget's estimate of body a's Cholesky factor, '123 MiB' or '1.2 GiB'.
  function factor_estimate(a) result(s)
    integer, intent(in) :: a
    character(len=:), allocatable :: s
    real(wp) :: nm, nf, mib
    character(len=24) :: buf
    mib = body_memory_mb(dsized%body(a), d%solver%factor, nm, nf)   ! the body's total; the factor's part:
    mib = 8.5_wp*nf/1048576.0_wp                              ! values and supernodal indices
    if (mib >= 1024.0_wp) then
      write (buf, '(f0.1,a)') mib/1024.0_wp, ' GiB'
    else
      write (buf, '(i0,a)') nint(mib), ' MiB'
    end if
    s = trim(buf)
  end function factor_estimate

  !> A signal before the outer iteration (during assembly, ordering, factorization or
  !! condensation, where the libraries cannot be interrupted safely): stop at the end of
  !! the phase with exit 4. There is nothing to checkpoint yet and nothing is written.
  subroutine check_interrupt(phase)
    character(len=*), intent(in) :: phase
    if (.not. par_any(stop_requested())) return
    res%status = STATUS_INTERRUPTED
    res%method = merge('robin     ', 'monolithic', d%solver%method == METHOD_ROBIN)
    code = EXIT_INTERRUPTED
    write (error_unit, '(a)') 'robin_contact: interrupted: signal '//i2s(pending_signal())//' during the '// &
      phase//'; stopped before the first outer iteration, so there is no checkpoint and nothing was written'
    tm%total = wtime() - t_start
    tm%peak_rss_mb = peak_rss_mb()
    call summary()
    call finish(code)
  end subroutine check_interrupt

  !> The closing lines. A summary that cannot be written (standard output on a full disk or
  !! a closed pipe) is a failure: scripts read the result: line.
  subroutine summary()
    real(wp) :: ftot, fres(2)
    character(len=1024) :: line(5)
    integer :: err(5), k
    if (me /= 0) return
    err = 0
    ftot = 0.0_wp
    fres = 0.0_wp
    if (allocated(res%lam)) then
      ftot = sum(res%lam)
      fres = contact_resultant(itf, 1, res%lam)
    end if
    write (line(1), '(a,i0,a,es10.3,a,es10.3,a,es10.3)') 'contact: resultant_on_body1='// &
      sci(fres(1), 5)//','//sci(fres(2), 5)//' normal_force_sum='//sci(ftot, 5)//' active=', res%active, &
      ' imbalance=', res%imbalance, ' penetration=', res%penetration, ' complementarity=', res%complementarity
    if (res%outer > 0) then
      line(2) = 'accuracy: |lam - lam_monolithic|/|lam| <= '//sci(res%error_bound)// &
        ' (a posteriori bound, cond(F1+F2) ~ '//sci(res%kappa)//')'
    else
      line(2) = 'accuracy: none (stopped before the first outer iteration: no contact forces to bound)'
    end if
    write (line(3), '(a,6(a,f0.3),a,f0.1,a,f0.1)') 'time:', ' assemble=', tm%assemble, ' factor=', tm%factor, &
      ' condense=', tm%condense, ' iterate=', tm%iterate, ' output=', tm%output, ' total=', tm%total, &
      ' peak_mb=', tm%peak_rss_mb, ' factor_mb=', tm%factor_mb
    write (line(4), '(a,a,a,a,a,i0,a,i0,a,i0,a,i0,a,i0,a,a,a,es8.2,a,a)') 'result: status=', status_name(res%status), &
      ' method=', trim(res%method), ' outer=', res%outer, ' inner=', res%inner, ' n1=', sys(1)%n, &
      ' n2=', sys(2)%n, ' m=', itf%m, ' delta=', fmt_real(d%solver%delta, '(f0.6)'), ' residual=', res%residual, &
      ' wall_s=', fmt_real(tm%total, '(f0.3)')
    ! the output line sits before the time line when a result file was written
    do k = 1, 4
      if (k == 3 .and. written) then
        call write_stdout_checked('output: '//trim(d%output%file), err(5))
      end if
      call write_stdout_checked(trim(line(k)), err(k))
    end do
    if (any(err /= 0)) then
      write (error_unit, '(a)') 'robin_contact: error: cannot write the summary to standard output '// &
        '(full disk or closed pipe?); the run''s status was '//status_name(res%status)
      code = EXIT_NUMERICAL
    end if
  end subroutine summary

  !> What a user whose Robin run did not converge should try next, in order: the robust
  !! operator and relaxation (the defaults), then the monolithic reference.
  function next_setting(sv) result(t)
    type(solver_cfg_t), intent(in) :: sv
    character(len=:), allocatable :: t
    if (sv%robin_operator /= ROBIN_HARMONIC) then
      t = "try &solver robin_operator='harmonic', delta=0.5 / (robust to material contrast), "// &
          "or method='monolithic'"
    else if (abs(sv%delta - 0.5_wp) > 0.01_wp) then
      t = "try &solver delta=0.5 / (the harmonic operator's best relaxation), or method='monolithic'"
    else
      t = "try &solver method='monolithic' / (one QP over both bodies, no outer iteration), "// &
          "or a larger max_outer"
    end if
  end function next_setting

  !> The effective deck without the settings that may change between a run and its
  !! restart (output, max_outer): a checkpoint is only accepted under the same key.
  function physics_key(d0) result(k)
    type(deck_t), intent(in) :: d0
    character(len=:), allocatable :: k
    type(deck_t) :: d1
    type(output_cfg_t) :: o
    d1 = d0
    d1%output = o
    d1%source = ''
    d1%title = ''
    d1%solver%max_outer = 1
    call deck_text(d1, k)
  end function physics_key

  !> The command line: DECK [OVERRIDE ...] [--restart FILE]. `--help`, `--version` and
  !! `--deck-reference` (anywhere) print to standard output and exit 0 without a deck; any
  !! other argument that starts with '-' is an unknown option (exit 1).
  subroutine parse_arguments(path, extra, restart)
    character(len=:), allocatable, intent(out) :: path
    character(len=4096), allocatable, intent(out) :: extra(:)
    character(len=:), allocatable, intent(out) :: restart
    integer :: n, i, l, k
    character(len=4096) :: arg
    character(len=*), parameter :: OPTIONS = 'the options are --help, --version, --deck-reference '// &
      'and --restart FILE.ckpt.h5 (robin_contact --help)'
    n = command_argument_count()
    i = 1
    do while (i <= n)
      call get_command_argument(i, arg, l)
      select case (trim(arg))
      case ('-h', '--help')
        call print_and_exit(deck_usage)
      case ('--version')
        call print_and_exit('robin_contact '//program_version)
      case ('--deck-reference')
        call print_and_exit(deck_reference())
      case ('--restart')
        i = i + 1   ! its file is not an option
      case default
        if (arg(1:1) == '-' .and. len_trim(arg) > 1) call fatal(EXIT_INPUT, 'unknown option '''// &
          trim(arg)//'''; '//OPTIONS)
      end select
      i = i + 1
    end do
    if (n < 1) call fatal(EXIT_INPUT, 'no deck file given'//achar(10)//deck_usage)
    call get_command_argument(1, arg, l)
    if (trim(arg) == '--restart') call fatal(EXIT_INPUT, 'no deck file given: the deck comes '// &
      'first, robin_contact DECK.nml [OVERRIDE ...] --restart FILE.ckpt.h5')
    path = trim(arg)
    restart = ''
    allocate (extra(n - 1))
    k = 0
    i = 2
    do while (i <= n)
      call get_command_argument(i, arg, l)
      if (l > len(arg)) call fatal(EXIT_INPUT, 'command-line argument too long')
      if (trim(arg) == '--restart') then
        if (i == n) call fatal(EXIT_INPUT, '--restart needs a checkpoint file (FILE.ckpt.h5)')
        call get_command_argument(i + 1, arg, l)
        restart = trim(arg)
        i = i + 2
        cycle
      end if
      k = k + 1
      extra(k) = arg
      i = i + 1
    end do
    extra = extra(1:k)
  end subroutine parse_arguments

  !> Write `text` (lines separated by LF, a final LF optional) to standard output (rank 0's
  !! in the MPI binary) and end the program with exit code 0 (3 if it cannot be written).
  subroutine print_and_exit(text)
    character(len=*), intent(in) :: text
    integer :: err, n
    n = len(text)
    if (n > 0) then
      if (text(n:n) == achar(10)) n = n - 1
    end if
    err = 0
    if (me == 0) call write_stdout_checked(text(1:n), err)
    if (err /= 0) call fatal(EXIT_NUMERICAL, 'cannot write to standard output (full disk or closed pipe?)')
    call finish(EXIT_OK)
  end subroutine print_and_exit

end program robin_contact
