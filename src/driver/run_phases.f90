!> The phases both back-ends share, in the driver's order: the back-end's choice, the
!! meshes and the assembly of every body, the contact rows, the restart, the finiteness of
!! the condensed data, the contact solve (rank 0), the displacements' rigid part, the
!! result file; and the check for a signal between the phases.
module run_phases
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use errors, only: error_t, warn, EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL, EXIT_INTERRUPTED, ERR_INPUT
  use fatal_errors, only: fail_on, fatal
  use config, only: METHOD_ROBIN, METHOD_MONOLITHIC, FACTOR_MUMPS, FACTOR_CHOICES, deck_t, body_force_of, stage_count, body_stiffness, &
                    solver_cfg_t, ROBIN_HARMONIC, ROBIN_STEKLOV, ELEM_Q1, ELEM_P1, ELEM_HEX8
  use space, only: NDIM
  use mesh, only: mesh_t, mesh_build, box_build, assign_cell_laws
  use elements_3d, only: kuhn_tets
  use gmsh_msh, only: msh_read, msh_read_shared
  use assembly, only: assemble_body, support_reactions
  use contact_interface, only: build_interface, slot_row, has_friction, DIR_NORMAL
  use contact_types, only: STATUS_FAILED, STATUS_DIVERGED, STATUS_INTERRUPTED, STATUS_CONVERGED, STATUS_NO_EQUILIBRIUM, anderson_history, &
                           contact_result_t, robin_state_t
  use robin_iteration, only: solve_robin
  use monolithic, only: solve_monolithic
  use error_estimate, only: error_bound
  use floating, only: rigid_rows, check_held, check_pressed, free_list, fixing_list, friction_edge
  use contact_common, only: gather
  use results, only: write_results, result_files, per_body_files
  use post_process, only: result_fields_t, prepare_fields, add_step
  use checkpoint, only: h5_checkpointer_t, checkpoint_read, checkpoint_read_steps, checkpoint_file, mesh_identity
  use files, only: remove_file, special_file, check_new_files
  use signals, only: stop_requested, pending_signal
  use sysinfo, only: peak_rss_mb
  use budget, only: body_memory_mb
  use strings, only: sci, i2s, word
  use sorting, only: largest_first
  use omp_lib, only: omp_get_max_threads, omp_set_max_active_levels, omp_set_num_threads
  use clock, only: wtime
  use cholmod_iface, only: cm_init
  use mpi_env, only: par_built, par_any
  use run_state, only: run_t, set_collective
  use run_backend, only: backend_t
  use serial_backend, only: serial_backend_t
  use mpi_backend, only: mpi_backend_t
  use run_summary, only: summary, step_line
  use load_history, only: plan_steps, set_step_loads
  use results, only: step_result_t
  implicit none (type, external)
  private

  public :: choose_backend, choose_threads, read_meshes, assemble_bodies, build_contact_line, read_restart, &
            factor_estimate, check_condensed, solve_contact, complete_displacements, write_output, &
            check_interrupt, solve_steps, check_output_names

contains

  !> The MPI back-end for factorization='mumps' (the MPI binary only), the serial one
  !! otherwise (one rank only).
  subroutine choose_backend(run, backend)
    type(run_t), intent(in) :: run                            !< the run: its deck and ranks
    class(backend_t), allocatable, intent(out) :: backend     !< the chosen back-end
    associate (deck => run%deck)
      if (deck%solver%factor%factorization == FACTOR_MUMPS) then
        if (.not. par_built) call fatal(EXIT_INPUT, 'deck '//trim(deck%source)// &
          ': factorization=''mumps'' needs the MPI binary: run mpirun -np N bin/robin_contact_mpi '// &
          trim(deck%source)//' (built by make MPI=1); this binary has no MPI or MUMPS')
        allocate (mpi_backend_t :: backend)
        backend%assembles_matrix = .false.
      else
        if (run%ranks > 1) call fatal(EXIT_INPUT, 'deck '//trim(deck%source)//': factorization='''// &
          word(FACTOR_CHOICES, deck%solver%factor%factorization)//''' runs on one rank, and this run has '// &
          i2s(run%ranks)//'; use factorization=''mumps'' or mpirun -np 1')
        allocate (serial_backend_t :: backend)
      end if
    end associate
  end subroutine choose_backend

  !> Every file the run may write (the result, its XDMF companions, the checkpoint, and
  !! their temporary names) can be made where the deck puts it, checked before any work:
  !! a name the file system cannot hold is bad input (exit 1), not a failure after the solve.
  subroutine check_output_names(run)
    type(run_t), intent(in) :: run   !< the run: its deck
    character(len=:), allocatable :: file
    character(len=len_trim(run%deck%output%file) + 32), allocatable :: name(:)
    type(error_t) :: err
    file = trim(run%deck%output%file)
    if (per_body_files(run%deck%output%xdmf, run%deck%nbody, max(1, run%deck%npair))) then
      call result_files(file, run%deck%nbody, max(1, run%deck%npair), name)
    else
      call result_files(file, 0, 1, name)
    end if
    call check_new_files(name, err)
    if (.not. err%failed()) call check_new_files([checkpoint_file(file)], err)
    call fail_on(err, 'deck '//trim(run%deck%source))
  end subroutine check_output_names

  !> The threads the user gives (OMP_NUM_THREADS): one per body at a time, the largest body
  !! first, and the interface-sized loops on the same threads; a thread without a body takes
  !! tiles of the others' factorizations (blas_tiles.c). BLAS stays on one thread: a
  !! threaded OpenBLAS cuts each call by its thread count, and the results must be the same
  !! to the last bit whatever the threads (measured: 2 BLAS threads per body moved a
  !! frictional result by 1e-8). CHOLMOD opens OpenMP regions of its own with a fixed num_threads(4);
  !! inside our region they are nested and run serially, but with one thread our region is
  !! inactive and CHOLMOD's would start 4 threads on the cores we use (measured: 10x slower
  !! factorization). So no region below ours is active.
  subroutine choose_threads(run)
    type(run_t), intent(inout) :: run   !< the run: its threads
    integer :: nthr
    ! BLAS on one thread from the start (its own threads would take the bodies' cores); an
    ! OpenMP build of OpenBLAS sets the program's OpenMP threads with its own: put them back
    nthr = omp_get_max_threads()
    call cm_init()
    call omp_set_num_threads(nthr)
    run%threads = max(1, nthr)
    if (run%threads == 1) then
      call omp_set_max_active_levels(0)
    else
      call omp_set_max_active_levels(1)
    end if
  end subroutine choose_threads

  !> Every body's mesh: the bodies that share one mesh file from it, read and parsed once;
  !! a body alone in its file from that file; the others structured from the deck. A body
  !! from a mesh file is sized by its node count (run%sized), and the memory is checked
  !! again with it.
  subroutine read_meshes(run, backend)
    type(run_t), intent(inout) :: run                  !< the run: its meshes
    class(backend_t), intent(inout) :: backend         !< checks the memory
    integer :: a, b, k
    type(error_t), allocatable :: err(:)
    logical, allocatable :: done(:)
    integer, allocatable :: ids(:)
    associate (deck => run%deck)
      run%nbody = deck%nbody
      allocate (run%meshes(deck%nbody), run%systems(deck%nbody), run%bodies(deck%nbody), err(deck%nbody), &
                done(deck%nbody), run%mesh_hex(deck%nbody))
      run%mesh_hex = ''
      do a = 1, deck%nbody   ! opening a FIFO or device would wait or read forever
        if (len_trim(deck%body(a)%mesh) == 0) cycle
        if (special_file(trim(deck%body(a)%mesh))) call fail_on(error_t(ERR_INPUT, 'body '//i2s(a)// &
          ": mesh file '"//trim(deck%body(a)%mesh)//"': is not a regular file (a folder, FIFO or device)"), &
          'deck '//trim(deck%source))
      end do
      ! bodies sharing a mesh file: the file parsed once for all of them
      done = .false.
      do a = 1, deck%nbody
        if (done(a) .or. len_trim(deck%body(a)%mesh) == 0) cycle
        ids = pack([(b, b=1, deck%nbody)], [(deck%body(b)%mesh == deck%body(a)%mesh, b=1, deck%nbody)])
        if (size(ids) < 2) cycle
        block
          type(mesh_t), allocatable :: shared(:)
          type(error_t), allocatable :: serr(:)
          character(len=16) :: hex
          allocate (shared(size(ids)), serr(size(ids)))
          call msh_read_shared(trim(deck%body(a)%mesh), [(deck%body(ids(k))%region, k=1, size(ids))], ids, shared, &
                               serr, run%threads, hex)
          do k = 1, size(ids)
            run%mesh_hex(ids(k)) = hex
            run%meshes(ids(k)) = shared(k)
            err(ids(k)) = serr(k)
            done(ids(k)) = .true.
          end do
        end block
      end do
      !$omp parallel do num_threads(run%threads) schedule(dynamic, 1)
      do a = 1, deck%nbody
        if (done(a)) cycle
        if (len_trim(deck%body(a)%mesh) > 0) then
          call msh_read(trim(deck%body(a)%mesh), trim(deck%body(a)%region), a, run%meshes(a), err(a), run%mesh_hex(a))
        else if (NDIM == 3) then
          call box_build(run%meshes(a), deck%body(a), kuhn_tets, err(a))
        else
          call mesh_build(run%meshes(a), deck%body(a), err(a))
        end if
      end do
      !$omp end parallel do
      do a = 1, deck%nbody   ! the mesh reader's message names the body
        call fail_on(err(a), 'deck '//trim(deck%source))
      end do
      do a = 1, deck%nbody   ! a meridian section lies at x = r >= 0
        run%meshes(a)%axisymmetric = deck%axisymmetric
        if (.not. deck%axisymmetric) cycle
        associate (xy => run%meshes(a)%xy)
          if (minval(xy(1, :)) < -1.0e-9_wp*max(maxval(xy(1, :)) - minval(xy(1, :)), &
                                                 maxval(xy(2, :)) - minval(xy(2, :)))) &
            call fail_on(error_t(ERR_INPUT, 'body '//i2s(a)//": mesh file '"//trim(deck%body(a)%mesh)// &
              "': a node lies at x = "//sci(minval(xy(1, :)))//', below the axis: with &scene plane = '// &
              "'axisymmetric' x is the radius, every node at x >= 0"), 'deck '//trim(deck%source))
        end associate
      end do
      do a = 1, deck%nbody   ! each cell's material, from the deck's regions
        block
          type(error_t) :: lerr
          integer :: bad, i, n
          call assign_cell_laws(run%meshes(a), deck%body(a), lerr, bad)
          if (.not. lerr%failed()) cycle
          n = 1
          do i = 1, deck%nregion     ! law bad is the (bad-1)-th region of body a
            if (deck%region(i)%body /= a) cycle
            n = n + 1
            if (n == bad) exit
          end do
          call fail_on(error_t(ERR_INPUT, 'the '//trim(deck%region(i)%origin)//" (body "//i2s(a)//", name = '"// &
            trim(deck%region(i)%name)//"'): mesh file '"//trim(deck%body(a)%mesh)//"': "//lerr%message), &
            'deck '//trim(deck%source))
        end block
      end do
      run%sized = deck
      if (any([(len_trim(deck%body(a)%mesh) > 0, a=1, deck%nbody)])) then
        do a = 1, deck%nbody
          if (len_trim(deck%body(a)%mesh) == 0) cycle
          if (NDIM == 3) then    ! a volume mesh: the cube of as many nodes (tetrahedra: six per grid cell)
            run%sized%body(a)%nx = max(1, nint(real(run%meshes(a)%nnode, wp)**(1.0_wp/3.0_wp)) - 1)
            run%sized%body(a)%ny = run%sized%body(a)%nx
            run%sized%body(a)%nz = max(1, run%meshes(a)%nnode/(run%sized%body(a)%nx + 1)**2 - 1)
            run%sized%body(a)%element = merge(ELEM_Q1, ELEM_P1, run%meshes(a)%element == ELEM_HEX8)
            cycle
          end if
          run%sized%body(a)%nx = max(1, nint(sqrt(real(run%meshes(a)%nnode, wp))) - 1)
          run%sized%body(a)%ny = max(1, run%meshes(a)%nnode/(run%sized%body(a)%nx + 1) - 1)
        end do
        call backend%check_memory(run, run%sized)
      end if
    end associate
  end subroutine read_meshes

  !> Every body's DOF numbering and loads, the bodies on the threads; the stiffness too
  !! unless each rank assembles its cells' share later (MUMPS). A body's contact groups
  !! (one per pair it is in) are the assembly's to check.
  subroutine assemble_bodies(run, matrix)
    type(run_t), intent(inout) :: run   !< the run: its systems
    logical, intent(in) :: matrix       !< assemble the stiffness
    type(error_t), allocatable :: err(:)
    integer, allocatable :: order(:)
    integer :: a, k
    associate (deck => run%deck)
      allocate (err(deck%nbody))
      run%plan = plan_steps(deck)
      order = largest_first([(run%meshes(a)%nnode, a=1, run%nbody)])
      !$omp parallel do num_threads(run%threads) schedule(dynamic, 1) private(a)
      do k = 1, deck%nbody
        a = order(k)
        if (size(run%plan) == 1) then
          call assemble_body(run%meshes(a), deck%body(a), deck%plane_strain, deck%traction, deck%ntraction, &
                             run%systems(a), err(a), boundaries=deck%boundary(1:deck%nboundary), matrix=matrix, &
                             contact_groups=body_groups(deck, a), body_load=body_force_of(deck, a, stage_count(deck)))
        else   ! each stage's load vectors too, which the steps combine
          call assemble_body(run%meshes(a), deck%body(a), deck%plane_strain, deck%traction, deck%ntraction, &
                             run%systems(a), err(a), boundaries=deck%boundary(1:deck%nboundary), matrix=matrix, &
                             contact_groups=body_groups(deck, a), nstage=run%plan(size(run%plan))%stage, &
                             body_load=body_force_of(deck, a, run%plan(size(run%plan))%stage))
        end if
      end do
      !$omp end parallel do
      do a = 1, deck%nbody
        ! assembly's messages name their body
        call fail_on(err(a), 'deck '//trim(deck%source))
      end do
    end associate
  end subroutine assemble_bodies

  !> The contact groups of body a, one per pair it takes part in ('' : its 'contact' side).
  function body_groups(deck, a) result(g)
    type(deck_t), intent(in) :: deck
    integer, intent(in) :: a
    character(len=128), allocatable :: g(:)
    integer :: p, s
    allocate (g(0))
    do p = 1, deck%npair
      do s = 1, 2
        if (deck%pair(p)%bodies(s) == a) g = [character(len=128) :: g, deck%pair(p)%body_group(s)]
      end do
    end do
  end function body_groups

  !> The contact rows of every pair; for a body held only by contact, its equilibrium
  !! rows, and whether the contact can hold it (exit 1 if not).
  subroutine build_contact_line(run)
    type(run_t), intent(inout) :: run   !< the run: its contact rows and bodies' rigid rows
    type(error_t) :: err
    integer :: a
    call build_interface(run%deck%body, run%deck%pair(1:run%deck%npair), run%deck%pairs_named, run%meshes, &
                         run%systems, run%contact_line, err)
    call fail_on(err, 'deck '//trim(run%deck%source))
    do a = 1, run%nbody
      call rigid_rows(run%contact_line, a, run%systems(a), run%bodies(a))
    end do
    if (sum(run%systems(:)%nrig) == 0) return
    ! one step: its loads checked here; a load history: each step's loads by solve_steps,
    ! before it is solved (the first step's as input, exit 1)
    if (size(run%plan) == 1) then
      call check_held(run%contact_line, run%systems, run%bodies, err)
      call fail_on(err, 'deck '//trim(run%deck%source))
      block
        character(len=:), allocatable :: edge
        edge = friction_edge(run%contact_line, run%systems, run%bodies)
        if (len(edge) > 0) call warn('deck '//trim(run%deck%source)//': '//edge)
      end block
    end if
    do a = 1, run%nbody
      associate (system => run%systems(a))
        if (system%nrig > 0) write (output_unit, '(a)') 'floating: body '//i2s(a)//' is held only by '// &
          'contact (free: '//free_list(system)//'); fixing DOFs for its generalized inverse: '//fixing_list(system, run%meshes(a)%node_tag)// &
          '; kernel check |K R|/(|K| |R|) = '//sci(system%rig_residual)
      end associate
    end do
  end subroutine build_contact_line

  !> The content hashes of the mesh files just read (of the bytes the reader parsed), which a
  !! checkpoint records; the checkpoint to restart from is input too: read and checked
  !! before any file is touched.
  subroutine read_restart(run)
    type(run_t), intent(inout) :: run   !< the run: its mesh hashes, Robin state and result
    type(error_t) :: err
    integer :: a, k
    type(contact_result_t), allocatable :: done(:)
    ! an array constructor, not the section body(:)%mesh, whose temporary the checked build reports
    call mesh_identity([(run%deck%body(a)%mesh, a=1, run%nbody)], run%mesh_ids, err, run%mesh_hex)
    call fail_on(err, 'deck '//trim(run%deck%source))
    if (len(run%restart_file) == 0) return
    call checkpoint_read(run%restart_file, run%key, run%mesh_ids, run%contact_line%m, run%nbody, &
                         anderson_history(run%nbody, run%contact_line%npair), run%deck%solver%max_outer, &
                         run%robin_state, run%result, err, signed=run%contact_line%dir > DIR_NORMAL)
    call fail_on(err)
    if (size(run%plan) > 1) then   ! in a load history: the step it resumes, and the steps before it
      call checkpoint_read_steps(run%restart_file, run%contact_line%m, run%nbody, size(run%plan), &
                                 run%restart_step, done, err)
      call fail_on(err)
      allocate (run%steps(size(done)))
      do k = 1, size(done)
        run%steps(k)%res = done(k)
      end do
    end if
  end subroutine read_restart

  !> The budget's estimate of body a's Cholesky factor (all bodies' without a), '123 MiB'
  !! or '1.2 GiB'.
  function factor_estimate(run, a) result(s)
    type(run_t), intent(in) :: run            !< the run: its sized deck
    integer, intent(in), optional :: a        !< the body
    character(len=:), allocatable :: s
    real(wp) :: nm, nf, mib, total
    integer :: b
    character(len=24) :: buf
    mib = 0.0_wp
    do b = 1, run%nbody
      if (present(a)) then
        if (b /= a) cycle
      end if
      total = body_memory_mb(run%sized%body(b), run%deck%solver%factor, nm, nf)   ! the body's total; the factor's part:
      mib = mib + 8.5_wp*nf/1048576.0_wp                                     ! values and supernodal indices
    end do
    if (mib >= 1024.0_wp) then
      write (buf, '(f0.1,a)') mib/1024.0_wp, ' GiB'
    else
      write (buf, '(i0,a)') nint(mib), ' MiB'
    end if
    s = trim(buf)
  end function factor_estimate

  !> A flexibility that is not finite is a stiffness out of double precision's range, an
  !! interface load that is not finite a prescribed displacement or load out of it (exit 3).
  subroutine check_condensed(run)
    type(run_t), intent(in) :: run   !< the run: its condensed bodies
    integer :: a
    type(error_t) :: err
    character(len=1024) :: msg
    real(wp) :: lo, hi
    do a = 1, run%nbody
      if (.not. all(ieee_is_finite(run%bodies(a)%flex))) then
        call body_stiffness(run%deck%body(a), lo, hi)
        write (msg, '(a,i0,a,es10.3,a,es10.3,a)') 'body ', a, ': its interface flexibility is not finite (stiffness ', &
          lo, ' to ', hi, '): the stiffness is out of the range of double precision; rescale the units'
        call fatal(EXIT_NUMERICAL, trim(msg))
      else if (.not. all(ieee_is_finite(run%bodies(a)%b))) then
        write (msg, '(a,i0,a)') 'body ', a, ': its interface load is not finite: its prescribed displacements '// &
          'or loads are out of the range of double precision; rescale the units'
        call fatal(EXIT_NUMERICAL, trim(msg))
      end if
    end do
    ! a floating body with no load along its free motions: is it pressed by a deformation?
    ! (every rank decides, from the broadcast F_a and b_a, so that all stop together)
    if (sum(run%systems(:)%nrig) == 0) return
    call check_pressed(run%systems, run%contact_line, run%bodies, err)
    call fail_on(err, 'deck '//trim(run%deck%source))
  end subroutine check_condensed

  !> The contact forces (rank 0; the other ranks wait for them): the Robin iteration with
  !! its checkpoints, or the monolithic QP; then the a posteriori error bound and, for a
  !! floating body, its load against its contact force.
  subroutine solve_contact(run)
    type(run_t), intent(inout), target :: run   !< the run: its contact result (its steps the checkpoint's)
    type(h5_checkpointer_t) :: ckpt
    integer :: a, rigid
    real(wp) :: scale
    character(len=:), allocatable :: ratio
    if (run%rank /= 0) return
    associate (deck => run%deck, result => run%result, contact_line => run%contact_line, bodies => run%bodies)
      rigid = 0
      if (contact_line%npair == 1) then
        do a = 1, 2
          if (contact_line%m > 0 .and. all(bodies(a)%flex == 0.0_wp)) rigid = a
        end do
      end if
      if (deck%solver%method == METHOD_MONOLITHIC) then
        call solve_monolithic(deck%solver, contact_line, bodies, result, stop_requested)
      else if (rigid > 0) then
        ! a body whose contact DOFs are all prescribed does not move on the contact: the
        ! problem is the other body's obstacle problem, one QP, which is also the Robin
        ! iteration's fixed point (doc/method.md, "A body rigid on the contact")
        write (output_unit, '(a)') 'robin: body '//i2s(rigid)//' does not move on the contact (every '// &
          'contact DOF prescribed): the contact problem is body '//i2s(3 - rigid)// &
          '''s obstacle problem, solved as one QP (method monolithic)'
        call solve_monolithic(deck%solver, contact_line, bodies, result, stop_requested)
      else
        ckpt%file = checkpoint_file(deck%output%file)
        ckpt%key = run%key
        ckpt%meshes = run%mesh_ids
        ckpt%every = deck%output%checkpoint_every
        if (size(run%plan) > 1) then   ! a restart resumes this step, the ones before replayed
          ckpt%step = run%step
          ckpt%done => run%steps(1:run%step - 1)
        end if
        if (run%history%step > 0 .and. run%robin_state%it == 0) then   ! a load step after the first
          call solve_robin(deck%solver, contact_line, bodies, result, output_unit, deck%output%progress_lines, &
                           run%robin_state, ckpt, stop_requested, run%history%obstacle, run%history%lam)
        else
          call solve_robin(deck%solver, contact_line, bodies, result, output_unit, deck%output%progress_lines, &
                           run%robin_state, ckpt, stop_requested)
        end if
        if (ckpt%err%failed()) call warn(ckpt%err%text())
        call steklov_fallback(run, ckpt)
      end if
      if (result%status == STATUS_FAILED) return
      call error_bound(contact_line, bodies, result)
      if (contact_line%m == 0) return
      do a = 1, run%nbody
        if (run%systems(a)%nrig == 0) cycle
        associate (g => bodies(a)%rg, e => bodies(a)%re, own => gather(result%lam_body, bodies(a)%slots), &
                   mean => result%lam(slot_row(bodies(a)%slots, contact_line%m)))
          ! e = 0 (pressed by a deformation only): judged against the contact forces' size
          if (all(e == 0.0_wp)) then
            scale = max(norm2(g)*norm2(mean), tiny(1.0_wp))
            ratio = '|G lam|/(|G| |lam|) = '
          else
            scale = norm2(e)
            ratio = '|G lam - e|/|e| = '
          end if
          write (output_unit, '(a)') 'equilibrium: body '//i2s(a)//' '//ratio// &
            sci(norm2(matmul(g, own) - e)/scale)//' (its own force), '// &
            sci(norm2(matmul(g, mean) - e)/scale)//' (mean force); rigid motion '// &
            'amplitudes '//trim(amplitudes(run, a))//'; SMALBE multiplier updates '// &
            i2s(result%eq_updates)
        end associate
      end do
    end associate
  end subroutine solve_contact

  !> The harmonic operator's known stall (doc/method.md, "Near-kernel"): where its iteration
  !! stagnates, the obstacles fixed but the bodies not agreeing (a Coulomb fit, a sphere's
  !! friction at the axis), the Steklov operator, whose S_1 + S_2 = F_1 + F_2 is well
  !! conditioned, goes on from its iterate, and the summary says so. A run that converges,
  !! diverges otherwise, or uses another operator is untouched.
  subroutine steklov_fallback(run, ckpt)
    type(run_t), intent(inout), target :: run
    type(h5_checkpointer_t), intent(inout) :: ckpt
    type(solver_cfg_t) :: steklov
    type(contact_result_t) :: harmonic
    type(robin_state_t) :: harmonic_state
    real(wp), allocatable :: g(:, :), lam(:, :)
    integer :: outer0
    associate (result => run%result)
      if (run%deck%solver%robin_operator /= ROBIN_HARMONIC .or. result%status /= STATUS_DIVERGED) return
      if (index(result%message, 'stagnated') == 0) return
      if (.not. allocated(run%robin_state%G) .or. .not. allocated(run%robin_state%lam)) return
      write (output_unit, '(a)') 'robin: the harmonic operator stalled ('//trim(result%message)// &
        '); the steklov operator goes on from its iterate'
      harmonic = result
      harmonic_state = run%robin_state
      outer0 = result%outer
      g = run%robin_state%G
      lam = run%robin_state%lam
      steklov = run%deck%solver
      steklov%robin_operator = ROBIN_STEKLOV
      run%robin_state%it = 0
      call solve_robin(steklov, run%contact_line, run%bodies, result, output_unit, run%deck%output%progress_lines, &
                       run%robin_state, ckpt, stop_requested, g, lam)
      if (ckpt%err%failed()) call warn(ckpt%err%text())
      if (result%status /= STATUS_CONVERGED .and. .not. result%residual < harmonic%residual) then
        ! no better (a material contrast the Steklov operator cannot take): the harmonic result
        write (output_unit, '(a)') 'robin: the steklov operator did no better ('//trim(result%message)// &
          '); the harmonic operator''s result stands'
        result = harmonic
        run%robin_state = harmonic_state
        return
      end if
      result%outer = result%outer + outer0
      result%message = trim(result%message)//' (after '//i2s(outer0)//' outer iterations of the harmonic '// &
                       'operator, which stalled, then the steklov operator)'
    end associate
  end subroutine steklov_fallback

  !> The contact forces and the displacements of every load step in turn (one step: the
  !! deck's loads at once). A step's loads are combined from the stages' vectors and only
  !! its interface load b_a is condensed again (the factors stay); it starts from the step
  !! before's obstacles and forces (run%history). A step that does not converge ends the
  !! loop, the steps before it and it recorded. On a restart in the middle of a history the
  !! steps before the checkpoint's are replayed from its forces (run%steps), not solved.
  subroutine solve_steps(run, backend)
    type(run_t), intent(inout) :: run              !< the run: its result, displacements and steps
    class(backend_t), intent(inout) :: backend     !< condenses, shares the forces, recovers
    integer :: k, a
    type(step_result_t), allocatable :: replayed(:)
    type(contact_result_t) :: resumed
    allocate (run%displacement(maxval(run%systems(:)%ndof), run%nbody))
    if (size(run%plan) == 1) then
      call solve_step(run, backend)
      return
    end if
    if (allocated(run%steps)) call move_alloc(run%steps, replayed)   ! from the checkpoint
    allocate (run%steps(0))
    resumed = run%result   ! a checkpoint's result of the step it resumes
    do k = 1, size(run%plan)
      run%step = k
      do a = 1, run%nbody
        call set_step_loads(run%systems(a), run%plan(k))
      end do
      call set_interference(run, k)
      ! whether the contact can balance this step's loads on the floating bodies: the first
      ! step's is input (exit 1), and a history ends at its first later step without a
      ! static equilibrium, the steps before it kept
      if (k >= run%restart_step .and. .not. step_held(run, k)) exit
      call backend%condense_load(run)
      if (k < run%restart_step) then
        call replay_step(run, backend, replayed(k)%res)
      else
        if (k == run%restart_step .and. k > 1) run%result = resumed
        if (k > run%restart_step) run%robin_state%it = 0   ! a fresh start (warm: run%history)
        call set_slip_origin(run)
        call solve_step(run, backend)
      end if
      call record_step(run, k)
      if (run%result%status /= STATUS_CONVERGED) exit
    end do
    ! the steps solved (record_step reserves room for more)
    if (k <= size(run%plan)) then
      if (run%result%status == STATUS_NO_EQUILIBRIUM) then
        k = k - 1
        ! the loads of the last step solved, whose displacement and forces the result holds
        ! (its reactions are K u - f with them)
        if (k >= 1) then
          do a = 1, run%nbody
            call set_step_loads(run%systems(a), run%plan(k))
          end do
        end if
      end if
    end if
    if (run%rank == 0 .and. size(run%steps) > min(k, size(run%plan))) call keep_steps(run, min(k, size(run%plan)))
  end subroutine solve_steps

  !> Can the contact balance step k's loads on the floating bodies (their rigid rows taken
  !! again; floating%check_held)? Step 1's failure is bad input (exit 1, nothing written,
  !! the step and its stage named). A later step's: run%result (the step before's) gets the
  !! status STATUS_NO_EQUILIBRIUM and a message naming the step, its stage and load factor,
  !! and the reason. Whether a body without a load is pressed by a deformation is decided
  !! once, with the deck (check_condensed): through the elastic bodies around it, a step's
  !! deformation may press it where the rigid test cannot see it.
  logical function step_held(run, k) result(held)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: k
    type(error_t) :: err
    integer :: a
    held = .true.
    if (sum(run%systems(:)%nrig) == 0) return
    do a = 1, run%nbody
      if (run%systems(a)%nrig > 0) call rigid_rows(run%contact_line, a, run%systems(a), run%bodies(a))
    end do
    call check_held(run%contact_line, run%systems, run%bodies, err)
    if (.not. err%failed()) then
      block
        character(len=:), allocatable :: edge
        edge = friction_edge(run%contact_line, run%systems, run%bodies)
        if (len(edge) > 0 .and. run%rank == 0) call warn('deck '//trim(run%deck%source)//': step '//i2s(k)// &
          ' (stage '//i2s(run%plan(k)%stage)//', load factor '//trim(sci(run%plan(k)%factor))//'): '//edge)
      end block
      return
    end if
    if (k == 1) then
      err%message = 'at step 1 of '//i2s(size(run%plan))//' (stage '//i2s(run%plan(1)%stage)//', load factor '// &
        trim(sci(run%plan(1)%factor))//'): '//trim(err%message)
      call fail_on(err, 'deck '//trim(run%deck%source))
    end if
    held = .false.
    run%result%status = STATUS_NO_EQUILIBRIUM
    run%result%message = 'no static equilibrium from step '//i2s(k)//' of '//i2s(size(run%plan))//' (stage '// &
      i2s(run%plan(k)%stage)//', load factor '//trim(sci(run%plan(k)%factor))//') on: '//trim(err%message)// &
      '; the '//i2s(k - 1)//' steps before it are in the result'
  end function step_held

  !> run%steps reduced to its first n entries (moved, not copied).
  subroutine keep_steps(run, n)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: n
    type(step_result_t), allocatable :: kept(:)
    integer :: i
    allocate (kept(n))
    do i = 1, n
      call move_step(run%steps(i), kept(i))
    end do
    call move_alloc(kept, run%steps)
  end subroutine keep_steps

  !> Step result a into b, its arrays moved (a's left unallocated).
  subroutine move_step(a, b)
    type(step_result_t), intent(inout) :: a, b
    b%stage = a%stage
    b%load_factor = a%load_factor
    call move_alloc(a%u, b%u)
    b%res = a%res
  end subroutine move_step

  !> An interference fit ramped over a stage (&contact interference_stage = s): the overlap
  !! (g0 < 0) of that pair's normal rows times stage s's factor in step k, 0 before the stage
  !! and 1 after it; run%g0_full keeps the geometry's gaps (doc/method.md, "Interference").
  subroutine set_interference(run, k)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: k            !< the step
    integer :: r, s
    real(wp) :: f
    if (.not. allocated(run%contact_line%g0) .or. run%deck%npair == 0) return
    if (.not. any(run%deck%pair(1:run%deck%npair)%interference_stage > 0)) return
    if (.not. allocated(run%g0_full)) run%g0_full = run%contact_line%g0
    associate (itf => run%contact_line, st => run%plan(k))
      do r = 1, size(itf%g0)
        s = run%deck%pair(itf%pair_of(r))%interference_stage
        if (s == 0 .or. run%g0_full(r) >= 0.0_wp) cycle
        if (allocated(itf%dir)) then
          if (itf%dir(r) /= DIR_NORMAL) cycle
        end if
        f = 1.0_wp
        if (st%stage < s) f = 0.0_wp
        if (st%stage == s) f = st%factor
        itf%g0(r) = f*run%g0_full(r)
      end do
    end associate
  end subroutine set_interference

  !> Friction acts on each load step's slip increment: the tangential rows' g0 (rank 0, which
  !! solves the contact) is the slip w_1 + w_2 the step before ended with, 0 at the first
  !! step (doc/method.md, "Friction": the load history).
  subroutine set_slip_origin(run)
    type(run_t), intent(inout) :: run
    if (run%rank /= 0 .or. .not. allocated(run%contact_line%dir)) return
    if (.not. has_friction(run%contact_line)) return
    associate (itf => run%contact_line, h => run%history)
      where (itf%dir > DIR_NORMAL) itf%g0 = 0.0_wp
      if (h%step > 0 .and. allocated(h%w)) then
        where (itf%dir > DIR_NORMAL) itf%g0 = h%w(:, 1) + h%w(:, 2)
      end if
    end associate
  end subroutine set_slip_origin

  !> One contact solve (rank 0) with the bodies' current interface loads, then every
  !! body's displacement under its forces.
  subroutine solve_step(run, backend)
    type(run_t), intent(inout) :: run
    class(backend_t), intent(inout) :: backend
    call set_collective(.false.)
    call solve_contact(run)
    call set_collective(.true.)
    call backend%share_contact_forces(run)
    run%displacement = 0.0_wp
    if (run%result%status /= STATUS_FAILED) call backend%recover(run)
    call complete_displacements(run)
  end subroutine solve_step

  !> A step a checkpoint holds whole: its forces (rank 0 has them) to every rank, then the
  !! displacements recovered under them, as the run that solved it did.
  subroutine replay_step(run, backend, res)
    type(run_t), intent(inout) :: run
    class(backend_t), intent(inout) :: backend
    type(contact_result_t), intent(in) :: res   !< the step's stored result (rank 0)
    if (run%rank == 0) run%result = res
    call backend%share_contact_forces(run)
    run%displacement = 0.0_wp
    call backend%recover(run)
    call complete_displacements(run)
  end subroutine replay_step

  !> Rank 0 keeps step k's result, prints its step: line and, for a converged step, hands
  !! its forces, interface displacements and obstacles to the next (run%history).
  subroutine record_step(run, k)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: k
    type(step_result_t), allocatable :: grown(:)
    integer :: i
    if (run%rank == 0) then
      if (k > size(run%steps)) then   ! room for twice as many: every step moved a bounded number of times
        allocate (grown(min(size(run%plan), max(k, 2*size(run%steps), 8))))
        do i = 1, size(run%steps)
          call move_step(run%steps(i), grown(i))
        end do
        call move_alloc(grown, run%steps)
      end if
      run%steps(k)%stage = run%plan(k)%stage
      run%steps(k)%load_factor = run%plan(k)%factor
      run%steps(k)%res = run%result
      run%steps(k)%u = run%displacement
      write (output_unit, '(a)') step_line(run, k)
      flush (output_unit)
      if (run%result%status == STATUS_CONVERGED) then
        run%history%step = k
        run%history%lam = run%result%lam_body
        run%history%w = run%result%w
        run%history%obstacle = run%result%obstacle
      end if
    end if
  end subroutine record_step

  !> Body a's rigid motion amplitudes (the displacement of its fixing DOFs), space-separated.
  function amplitudes(run, a) result(t)
    type(run_t), intent(in) :: run
    integer, intent(in) :: a
    character(len=128) :: t
    integer :: k
    t = ''
    do k = 1, run%systems(a)%nrig
      t = trim(t)//' '//sci(run%result%rigid(k, a))
    end do
    t = adjustl(t)
  end function amplitudes

  !> A floating body's rigid part, u_a = K_a^+ (f_a - B_a' lam) + R_a alpha_a (rank 0,
  !! which writes); displacements that are not finite are a failure, never a result.
  subroutine complete_displacements(run)
    type(run_t), intent(inout) :: run   !< the run: its displacements and status
    integer :: a
    if (run%result%status == STATUS_FAILED) return
    if (run%rank == 0) then
      do a = 1, run%nbody
        associate (system => run%systems(a))
          if (system%nrig > 0) run%displacement(1:system%ndof, a) = run%displacement(1:system%ndof, a) + &
                                                              matmul(system%rig, run%result%rigid(1:system%nrig, a))
        end associate
      end do
    end if
    if (.not. all(ieee_is_finite(run%displacement))) then
      run%result%status = STATUS_FAILED
      run%result%message = 'the displacements are not finite: the problem is beyond double precision; rescale the units'
    end if
  end subroutine complete_displacements

  !> The supports' forces on every body (K u - f at its prescribed DOFs) of the final result,
  !! once, for the result file and the summary's reaction: lines; bodies in parallel.
  subroutine support_forces(run)
    type(run_t), intent(inout) :: run   !< the run: its reactions
    real(wp), allocatable :: mag(:)
    integer :: a
    if (allocated(run%reaction)) deallocate (run%reaction, run%reaction_mag)
    allocate (run%reaction(size(run%displacement, 1), run%nbody), run%reaction_mag(run%nbody))
    run%reaction = 0.0_wp
    !$omp parallel do num_threads(run%threads) schedule(dynamic, 1) private(mag)
    do a = 1, run%nbody
      associate (sy => run%systems(a))
        allocate (mag(sy%ndof))
        call support_reactions(run%meshes(a), run%deck%body(a), run%deck%plane_strain, sy, &
                               run%displacement(1:sy%ndof, a), sy%f_applied, run%reaction(1:sy%ndof, a), mag)
        run%reaction_mag(a) = sum(mag)
        deallocate (mag)
      end associate
    end do
    !$omp end parallel do
  end subroutine support_forces

  !> The result file (rank 0, unless the run failed). A converged run has no use for its
  !! checkpoint; a run that stopped keeps it. An earlier result at this path stays until
  !! this one replaces it whole; a run that fails leaves it untouched.
  subroutine write_output(run)
    type(run_t), intent(inout), target :: run   !< the run: whether its result was written
    type(error_t) :: err
    type(result_fields_t) :: fields
    integer :: stale, k
    if (run%code == EXIT_NUMERICAL .or. run%rank /= 0) return
    call support_forces(run)
    run%timing%peak_rss_mb = peak_rss_mb()
    run%timing%total = wtime() - run%t_start
    stale = 0
    ! the fields the file shows: the contact ones now, each body's as the writer writes it
    call prepare_fields(fields, run%deck, run%meshes, run%systems, run%contact_line, run%result, run%displacement, &
                        run%reaction)
    if (size(run%plan) > 1) then   ! every load step's result too
      if (allocated(run%steps)) then
        do k = 1, size(run%steps)
          call add_step(fields, run%steps(k)%stage, run%steps(k)%load_factor, run%steps(k)%res, run%steps(k)%u)
        end do
      end if
      call write_results(run%deck%output%file, run%deck, run%meshes, run%systems, fields, run%displacement, &
                         run%timing, err, run%steps, threads=run%threads, stale=stale)
    else
      call write_results(run%deck%output%file, run%deck, run%meshes, run%systems, fields, run%displacement, &
                         run%timing, err, threads=run%threads, stale=stale)
    end if
    run%written = .not. err%failed()
    call fail_on(err, 'output')
    if (stale > 0) write (output_unit, '(a)') 'output: removed '//i2s(stale)//' stale file'// &
      trim(merge('s', ' ', stale > 1))//' of an earlier result beside '//trim(run%deck%output%file)// &
      ' (its XDMF files of bodies or pairs this result does not have)'
    if (run%code == EXIT_OK) call remove_file(checkpoint_file(run%deck%output%file))
  end subroutine write_output

  !> A signal before the outer iteration (during assembly, ordering, factorization or
  !! condensation, where the libraries cannot be interrupted safely): stop at the end of
  !! the phase with exit 4. There is nothing to checkpoint yet and nothing is written.
  subroutine check_interrupt(run, backend, phase)
    type(run_t), intent(inout) :: run              !< the run
    class(backend_t), intent(inout) :: backend     !< ends the run
    character(len=*), intent(in) :: phase          !< the phase just ended
    if (.not. par_any(stop_requested())) return
    run%result%status = STATUS_INTERRUPTED
    run%result%method = run%deck%solver%method
    run%code = EXIT_INTERRUPTED
    write (error_unit, '(a)') 'robin_contact: interrupted: signal '//i2s(pending_signal())//' during the '// &
      phase//'; stopped before the first outer iteration, so there is no checkpoint and nothing was written'
    run%timing%total = wtime() - run%t_start
    run%timing%peak_rss_mb = peak_rss_mb()
    call summary(run)
    call backend%finish(run)
  end subroutine check_interrupt

end module run_phases
