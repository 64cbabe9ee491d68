!> The MPI back-end (factorization='mumps'): the bodies mapped to the ranks
!! (budget%body_rank_map: a group of ranks per body, or several bodies per rank when the
!! ranks are fewer); each rank computes its share of its bodies' element matrices and
!! factorizes them by MUMPS (each body's factorization%mumps_factor_t, through the same
!! condense routines as the serial path); the bodies' hosts broadcast the condensed data, rank 0 alone
!! iterates and broadcasts the contact forces, and every rank ends with rank 0's exit code.
module mpi_backend
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit
  use errors, only: error_t, EXIT_INPUT
  use fatal_errors, only: fatal, terminate, fail_on
  use config, only: deck_t
  use assembly, only: expand, cell_triplets
  use contact_types, only: STATUS_FAILED
  use sysinfo, only: peak_rss_mb, node_memory_limit_mb, process_memory_limit_mb
  use budget, only: rank_memory_mb, check_budget_ranks, body_rank_map
  use strings, only: i2s
  use mpi_env, only: par_finalize, par_split, par_bcast_reals, par_bcast_ints, par_agree, par_max_real, &
                     par_sum_real, par_node_sum
  use factorization, only: new_factor
  use run_state, only: run_t
  use contact_common, only: gather
  use run_backend, only: backend_t
  use condense, only: factor_body, condense_body, interface_load, recover_displacement, prescribed_part
  use floating, only: rigid_rows
  implicit none (type, external)
  private

  !> The ranks' groups (each body's MUMPS factor is its body's, run%bodies(a)%fac).
  type, extends(backend_t), public :: mpi_backend_t
    integer, allocatable :: host(:)         !< (nbody) the world rank hosting each body's group
    integer :: group_comm = 0               !< this rank's group (all its bodies')
    integer, allocatable :: group_rank(:)   !< (nbody) this rank within each of its bodies' groups
    integer, allocatable :: group_size(:)   !< (nbody) ranks of each body's group
    logical, allocatable :: mine(:)         !< (nbody) this rank works on the body
    real(wp) :: assembly_peak_mb = 0.0_wp   !< this rank's peak RSS when the factorization starts [MiB]
    type(error_t), allocatable :: err(:)    !< (nbody) each body's failure in the current phase, if any
  contains
    procedure :: check_memory, factor, condense, condense_load, record_factor_memory, share_contact_forces, recover, &
                 agree_code, report_ranks, finish
    procedure, private :: split_groups, agree_fatal
  end type mpi_backend_t

contains

  !> Each rank's estimate (its share of its bodies' factors, the meshes of every body)
  !! against ulimit -v, and the sum over the ranks of each node against the node's memory;
  !! every rank agrees (exit 1, nothing allocated yet).
  subroutine check_memory(self, run, the_deck)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(in) :: run          !< the run: its rank and ranks
    type(deck_t), intent(in) :: the_deck    !< the deck to size
    real(wp) :: est, node_est
    integer :: node_ranks, cat
    type(error_t) :: err
    est = rank_memory_mb(the_deck, run%ranks, run%rank)
    call par_node_sum(est, node_est, node_ranks)
    call check_budget_ranks(the_deck, run%ranks, run%rank, est, node_est, node_ranks, node_memory_limit_mb(), &
                            process_memory_limit_mb(), err)
    if (err%failed()) then
      cat = err%category     ! not err%category itself: set writes it
      call err%set(cat, 'deck '//trim(the_deck%source)//': '//err%text())
    end if
    call par_agree(err)
    call fail_on(err)
  end subroutine check_memory

  !> Map the bodies to the ranks and split the ranks into their groups, then each rank
  !! assembles its share of its bodies' cells (rank r of a group of g: cells
  !! r*nc/g+1 .. (r+1)*nc/g) and factorizes them by MUMPS, the largest body first.
  subroutine factor(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies factorized
    integer, allocatable :: irn(:), jcn(:)
    real(wp), allocatable :: kval(:)
    integer :: a, first, last
    call self%split_groups(run)
    do a = 1, run%nbody
      call self%err(a)%clear()
      if (.not. self%mine(a)) cycle
      first = self%group_rank(a)*run%meshes(a)%ncell/self%group_size(a) + 1
      last = (self%group_rank(a) + 1)*run%meshes(a)%ncell/self%group_size(a)
      call cell_triplets(run%meshes(a), run%deck%body(a), run%deck%plane_strain, run%systems(a), first, last, &
                         irn, jcn, kval, self%err(a))
      if (.not. self%err(a)%failed()) call factor_body(run%deck%solver%factor, run%contact_line, a, run%meshes(a), &
                                                       run%systems(a), run%bodies(a), self%err(a), self%group_comm, &
                                                       irn, jcn, kval)
      if (allocated(irn)) deallocate (irn, jcn, kval)
    end do
    call self%agree_fatal('factorization failed')
  end subroutine factor

  !> The body-to-rank map (budget%body_rank_map, on the sized deck, the same on every rank)
  !! and the ranks' communicators (MPI_Comm_split): with a rank per body at least, one
  !! group of consecutive ranks per body (world rank 0 hosts body 1); with fewer, each rank
  !! alone in its communicator, for all its bodies (each body on one rank).
  subroutine split_groups(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run
    integer :: a, nb, color
    character(len=:), allocatable :: line
    self%assembly_peak_mb = peak_rss_mb()   ! meshes, numbering and loads of every body
    nb = run%nbody
    allocate (self%host(nb), self%group_size(nb), self%group_rank(nb), self%mine(nb), self%err(nb))
    call body_rank_map(run%sized, run%ranks, self%host, self%group_size)
    self%mine = run%rank >= self%host .and. run%rank < self%host + self%group_size
    self%group_rank = merge(run%rank - self%host, 0, self%mine)
    do a = 1, nb
      if (self%group_size(a) > run%meshes(a)%ncell) call fatal(EXIT_INPUT, 'deck '//trim(run%deck%source)// &
        ': '//i2s(self%group_size(a))//' ranks for body '//i2s(a)//', which has '// &
        i2s(run%meshes(a)%ncell)//' cells: use fewer ranks (at most one per cell of each body)')
    end do
    color = run%rank
    if (run%ranks >= nb) color = findloc(self%mine, .true., 1)
    call par_split(color, self%group_comm)
    ! every rank has every body's factor object: its own bodies' are factorized, the others
    ! receive their sizes (share_condensed)
    do a = 1, nb
      call new_factor(run%deck%solver%factor, a, run%bodies(a)%fac, self%group_comm)
    end do
    if (run%ranks == 1) return
    if (run%ranks >= nb) then
      line = 'mumps:'
      do a = 1, nb
        if (a > 1) line = line//','
        line = line//' '//i2s(self%group_size(a))//' rank(s) on body '//i2s(a)
      end do
    else
      line = 'mumps: '//i2s(nb)//' bodies on '//i2s(run%ranks)//' ranks, each body on one rank (the largest '// &
             'first to the least loaded rank), at most '//i2s(maxval([(count(self%host == a - 1), a=1, run%ranks)]))// &
             ' per rank'
    end if
    write (output_unit, '(a)') line
  end subroutine split_groups

  !> Each group condenses its body; every rank then receives every body's condensed data.
  subroutine condense(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies condensed
    integer :: a
    do a = 1, run%nbody
      if (self%mine(a)) call condense_body(run%systems(a), run%bodies(a), self%err(a))
    end do
    call self%agree_fatal('condensation failed')
    call share_condensed(self, run)
  end subroutine condense

  !> Each group's host sends its body's F_a, b_a, the proximal weight, F_a's rank and
  !! kernel and the factor's size to every rank (the body's m and slots every rank has,
  !! from floating%rigid_rows).
  subroutine share_condensed(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run
    integer :: b, iv(1), m
    real(wp) :: rv(5)
    real(wp), allocatable :: max_rank_mb(:)
    do b = 1, run%nbody
      associate (cbody => run%bodies(b), fac => run%bodies(b)%fac)
        m = cbody%m
        if (.not. (self%mine(b) .and. fac%holds_result())) then
          if (allocated(cbody%flex)) deallocate (cbody%flex)
          allocate (cbody%flex(m, m))
        end if
        if (.not. allocated(cbody%b)) allocate (cbody%b(m))
        call par_bcast_reals(cbody%flex, m*m, self%host(b))
        call par_bcast_reals(cbody%b, m, self%host(b))
        rv = [cbody%prox, fac%stats%mem_bytes, fac%stats%max_rank_mb, fac%stats%factor_mb, fac%stats%tiles]
        call par_bcast_reals(rv, 5, self%host(b))
        cbody%prox = rv(1)
        fac%stats%mem_bytes = rv(2)
        fac%stats%max_rank_mb = rv(3)
        fac%stats%factor_mb = rv(4)
        fac%stats%tiles = rv(5)
        iv(1) = cbody%rank
        call par_bcast_ints(iv, 1, self%host(b))
        cbody%rank = iv(1)
        ! the kernel basis of a singular F_a (flex_rank), or the basis of its range when that
        ! is the smaller part (condense `low_rank_range`), which the harmonic operator's
        ! proximal term needs on rank 0 as much as on the body's host
        call share_basis(cbody%kern, .not. (self%mine(b) .and. fac%holds_result()), m, self%host(b))
        call share_basis(cbody%rng, .not. (self%mine(b) .and. fac%holds_result()), m, self%host(b))
      end associate
      call self%err(b)%clear()
    end do
    max_rank_mb = [(run%bodies(b)%fac%stats%max_rank_mb, b=1, run%nbody)]
    if (run%nbody == 2) then
      write (output_unit, '(a,2(f0.1,a))') 'mumps: largest rank''s factorization memory: body 1 ', &
        max_rank_mb(1), ' MB, body 2 ', max_rank_mb(2), ' MB'
    else
      write (output_unit, '(a,f0.1,a,i0,a)') 'mumps: largest rank''s factorization memory ', &
        maxval(max_rank_mb), ' MB (body ', maxloc(max_rank_mb, 1), ')'
    end if
  end subroutine share_condensed

  !> Broadcast an (m, k) basis from the host (k = -1 on the host: none, left unallocated);
  !! `receives` on the ranks that take it.
  subroutine share_basis(basis, receives, m, host)
    real(wp), allocatable, intent(inout) :: basis(:, :)
    logical, intent(in) :: receives
    integer, intent(in) :: m, host
    integer :: iv(1)
    iv(1) = -1
    if (allocated(basis)) iv(1) = size(basis, 2)
    call par_bcast_ints(iv, 1, host)
    if (iv(1) < 0) return
    if (receives) then
      if (allocated(basis)) deallocate (basis)
      allocate (basis(m, iv(1)))
    end if
    if (iv(1) > 0) call par_bcast_reals(basis, m*iv(1), host)
  end subroutine share_basis

  !> Each group's b_a for the current step's loads (one MUMPS solve), sent to every rank;
  !! every rank then has each floating body's load along its free motions.
  subroutine condense_load(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies' interface loads
    integer :: a
    do a = 1, run%nbody
      call self%err(a)%clear()
      if (.not. self%mine(a)) cycle
      call prescribed_part(run%contact_line, run%systems(a), run%bodies(a))
      call interface_load(run%systems(a), run%bodies(a), self%err(a))
    end do
    call self%agree_fatal('load step condensation failed')
    do a = 1, run%nbody
      call par_bcast_reals(run%bodies(a)%b, run%bodies(a)%m, self%host(a))
      if (run%systems(a)%nrig > 0) call rigid_rows(run%contact_line, a, run%systems(a), run%bodies(a))
    end do
  end subroutine condense_load

  !> The MUMPS factorizations' memory [MiB].
  subroutine record_factor_memory(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its timing
    integer :: a
    run%timing%factor_mb = sum([(run%bodies(a)%fac%stats%mem_bytes, a=1, run%nbody)])/1048576.0_wp
    run%timing%factor_tiles = sum([(run%bodies(a)%fac%stats%tiles, a=1, run%nbody)])
  end subroutine record_factor_memory

  !> Rank 0's contact forces and status to every rank (the others need lam to recover their
  !! bodies' displacements, and the status to end alike).
  subroutine share_contact_forces(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its contact result
    integer :: iv(1)
    iv(1) = run%result%status
    call par_bcast_ints(iv, 1, 0)
    if (run%rank /= 0) then
      run%result%status = iv(1)
      if (allocated(run%result%lam_body)) deallocate (run%result%lam_body)
      allocate (run%result%lam_body(run%contact_line%m, 2))
    end if
    if (iv(1) /= STATUS_FAILED) call par_bcast_reals(run%result%lam_body, 2*run%contact_line%m, 0)
  end subroutine share_contact_forces

  !> Each group solves its body under its contact forces; the hosts send the displacements
  !! to rank 0 (broadcast: every rank receives them).
  subroutine recover(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its displacements
    integer :: b
    real(wp), allocatable :: uf(:)
    do b = 1, run%nbody
      call self%err(b)%clear()
      if (.not. self%mine(b)) cycle
      allocate (uf(run%systems(b)%n))
      uf = 0.0_wp
      call recover_displacement(run%systems(b), run%bodies(b), gather(run%result%lam_body, run%bodies(b)%slots), &
                                uf, self%err(b))
      if (run%bodies(b)%fac%holds_result()) call expand(run%systems(b), uf, run%displacement(1:run%systems(b)%ndof, b))
      deallocate (uf)
    end do
    call self%agree_fatal('displacement recovery failed')
    do b = 1, run%nbody
      if (self%host(b) /= 0) call par_bcast_reals(run%displacement(1, b), run%systems(b)%ndof, self%host(b))
    end do
  end subroutine recover

  !> Rank 0 decides the exit code (the output may have failed there).
  subroutine agree_code(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its exit code
    integer :: iv(1)
    iv(1) = run%code
    call par_bcast_ints(iv, 1, 0)
    run%code = iv(1)
  end subroutine agree_code

  !> One line with the largest peak resident memory (VmHWM, getrusage) of any rank, which
  !! rank, and the sum over the ranks (what the job needs on one node); the largest peak
  !! at the start of the factorization tells the meshes' and loads' share. Then one line
  !! per rank: its bodies, its share of their MUMPS factors (INFO(9)) and its peak.
  !! Collective.
  subroutine report_ranks(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run
    real(wp) :: pmax, psum, amax, rv(2)
    integer :: where, awhere, r, a, iv(run%nbody)
    character(len=:), allocatable :: list
    call par_max_real(peak_rss_mb(), pmax, where)
    psum = par_sum_real(peak_rss_mb())
    call par_max_real(self%assembly_peak_mb, amax, awhere)
    write (output_unit, '(a,i0,a,f0.1,a,i0,a,f0.1,a,f0.1)') 'mpi: ranks=', run%ranks, ' peak_rss_max_rank_mb=', pmax, &
      ' max_rank=', where, ' peak_rss_sum_mb=', psum, ' assembly_peak_max_rank_mb=', amax
    if (.not. allocated(self%mine)) return
    do r = 0, run%ranks - 1
      rv = [0.0_wp, peak_rss_mb()]
      do a = 1, run%nbody
        if (self%mine(a)) rv(1) = rv(1) + run%bodies(a)%fac%stats%rank_factor_mb
      end do
      iv = merge(1, 0, self%mine)
      call par_bcast_reals(rv, 2, r)
      call par_bcast_ints(iv, run%nbody, r)
      list = ''
      do a = 1, run%nbody
        if (iv(a) /= 1) cycle
        if (len(list) > 0) list = list//','
        list = list//i2s(a)
      end do
      if (run%rank == 0) write (output_unit, '(a,i0,a,a,a,f0.3,a,f0.1)') 'mpi: rank=', r, ' bodies=', &
        list, ' factor_mb=', rv(1), ' peak_rss_mb=', rv(2)
    end do
    flush (output_unit)
  end subroutine report_ranks

  !> Every rank learns the worst status of the bodies' groups; a failure is fatal on all
  !! ranks, with the exit code of its category and the message of the lowest failing rank.
  subroutine agree_fatal(self, what)
    class(mpi_backend_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    integer :: b
    type(error_t) :: err
    do b = size(self%err), 1, -1
      if (self%err(b)%failed()) &
        call err%set(self%err(b)%category, 'body '//i2s(b)//': '//what//': '//self%err(b)%text())
    end do
    call par_agree(err)
    call fail_on(err)
  end subroutine agree_fatal

  !> End the run with its code on every rank: the MUMPS instances freed, MPI finalized.
  subroutine finish(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its exit code
    integer :: b
    if (allocated(self%mine)) then
      do b = 1, run%nbody
        if (self%mine(b)) call run%bodies(b)%fac%free()
      end do
    end if
    call par_finalize()
    call terminate(run%code)
  end subroutine finish

end module mpi_backend
