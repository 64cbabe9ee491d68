!> The MPI back-end (factorization='mumps'): one group of ranks per body computes its
!! share of the body's element matrices and factorizes it by MUMPS; the groups' hosts
!! broadcast the condensed data, rank 0 alone iterates and broadcasts the contact forces,
!! and every rank ends with rank 0's exit code.
module mpi_backend
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit
  use errors, only: fatal, terminate, error_t, exit_code, EXIT_INPUT
  use config, only: deck_t
  use assembly, only: expand, cell_triplets
  use contact_types, only: STATUS_FAILED
  use sysinfo, only: peak_rss_mb, node_memory_limit_mb, process_memory_limit_mb
  use budget, only: rank_memory_mb, check_budget_ranks
  use strings, only: i2s, body_label
  use mpi_env, only: par_finalize, par_split, par_bcast_reals, par_bcast_ints, par_agree, par_max_real, &
                     par_sum_real, par_node_sum
  use mumps_iface, only: mumps_t, mumps_end
  use condense_mumps, only: factor_body_mumps, condense_body_mumps, recover_displacement_mumps
  use run_state, only: run_t
  use contact_common, only: gather
  use run_backend, only: backend_t
  implicit none (type, external)
  private

  !> The ranks' groups and each body's MUMPS instance.
  type, extends(backend_t), public :: mpi_backend_t
    integer :: host(2) = 0                  !< the world rank hosting each body's group
    integer :: group_comm = 0               !< this rank's group
    integer :: group_rank(2) = 0            !< this rank within each body's group
    integer :: group_size(2) = 1            !< ranks of each body's group
    logical :: mine(2) = .true.             !< this rank works on the body
    real(wp) :: assembly_peak_mb = 0.0_wp   !< this rank's peak RSS when the factorization starts [MiB]
    type(mumps_t) :: solver(2)              !< each body's MUMPS instance
    type(error_t) :: err(2)                 !< each body's failure in the current phase, if any
  contains
    procedure :: check_memory, factor, condense, record_factor_memory, share_contact_forces, recover, &
                 agree_code, report_ranks, finish
    procedure, private :: split_groups, agree_fatal
  end type mpi_backend_t

contains

  !> Each rank's estimate (its share of its body's factor, the meshes of both bodies)
  !! against ulimit -v, and the sum over the ranks of each node against the node's memory;
  !! every rank agrees (exit 1, nothing allocated yet).
  subroutine check_memory(self, run, the_deck)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(in) :: run          !< the run: its rank and ranks
    type(deck_t), intent(in) :: the_deck    !< the deck to size
    real(wp) :: est, node_est
    integer :: st, node_ranks
    type(error_t) :: err
    character(len=1024) :: m1
    est = rank_memory_mb(the_deck, run%ranks, run%rank)
    call par_node_sum(est, node_est, node_ranks)
    call check_budget_ranks(the_deck, run%ranks, run%rank, est, node_est, node_ranks, node_memory_limit_mb(), &
                            process_memory_limit_mb(), err)
    st = exit_code(err)
    m1 = ''
    if (err%failed()) m1 = 'deck '//trim(the_deck%source)//': '//err%text()
    call par_agree(st, m1)
    if (st /= 0) call fatal(st, trim(m1))
  end subroutine check_memory

  !> Split the ranks into their groups, then each group assembles its share of its body's
  !! cells (rank r of g: cells r*nc/g+1 .. (r+1)*nc/g) and factorizes it by MUMPS.
  subroutine factor(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies factorized
    integer, allocatable :: irn(:), jcn(:)
    real(wp), allocatable :: kval(:)
    integer :: a, first, last
    call self%split_groups(run)
    do a = 1, 2
      call self%err(a)%clear()
      if (.not. self%mine(a)) cycle
      first = self%group_rank(a)*run%meshes(a)%ncell/self%group_size(a) + 1
      last = (self%group_rank(a) + 1)*run%meshes(a)%ncell/self%group_size(a)
      call cell_triplets(run%meshes(a), run%deck%body(a), run%deck%plane_strain, run%systems(a), first, last, &
                         irn, jcn, kval, self%err(a))
      if (.not. self%err(a)%failed()) call factor_body_mumps(run%contact_line, a, run%systems(a), irn, jcn, kval, &
                                                             self%group_comm, run%bodies(a), self%solver(a), self%err(a))
      if (allocated(irn)) deallocate (irn, jcn, kval)
    end do
    call self%agree_fatal('factorization failed')
  end subroutine factor

  !> Split the ranks into one group per body (MPI_Comm_split): one rank does both bodies
  !! in turn; otherwise half each, an odd one out to the body with more unknowns. The
  !! lower world ranks form body 1's group, so world rank 0 hosts body 1.
  subroutine split_groups(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(in) :: run
    integer :: g1, b
    self%assembly_peak_mb = peak_rss_mb()   ! meshes, numbering and loads of both bodies
    if (run%ranks == 1) then
      self%mine = .true.
      self%host = 0
      call par_split(0, self%group_comm)
      return
    end if
    g1 = run%ranks/2
    if (mod(run%ranks, 2) == 1 .and. run%systems(1)%n >= run%systems(2)%n) g1 = g1 + 1
    self%host = [0, g1]
    self%mine = [run%rank < g1, run%rank >= g1]
    self%group_size = [g1, run%ranks - g1]
    self%group_rank = [run%rank, run%rank - g1]
    do b = 1, 2
      if (self%group_size(b) > run%meshes(b)%ncell) call fatal(EXIT_INPUT, 'deck '//trim(run%deck%source)// &
        ': '//i2s(self%group_size(b))//' ranks for body '//body_label(b)//', which has '// &
        i2s(run%meshes(b)%ncell)//' cells: use at most '// &
        i2s(2*min(run%meshes(1)%ncell, run%meshes(2)%ncell))//' ranks')
    end do
    call par_split(merge(1, 2, run%rank < g1), self%group_comm)
    write (output_unit, '(a,i0,a,i0,a)') 'mumps: ', g1, ' rank(s) on body 1, ', run%ranks - g1, ' on body 2'
  end subroutine split_groups

  !> Each group condenses its body; every rank then receives both bodies' condensed data.
  subroutine condense(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies condensed
    integer :: a
    do a = 1, 2
      if (self%mine(a)) call condense_body_mumps(run%systems(a), run%bodies(a), self%solver(a), a, self%err(a))
    end do
    call self%agree_fatal('condensation failed')
    call share_condensed(self, run)
  end subroutine condense

  !> Each group's host sends its body's F_a, b_a and the proximal weight to every rank.
  subroutine share_condensed(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run
    integer :: b, iv(1), m
    real(wp) :: rv(3)
    m = run%contact_line%m
    do b = 1, 2
      associate (body => run%bodies(b), solver => self%solver(b))
        if (.not. (self%mine(b) .and. solver%host)) then
          if (allocated(body%flex)) deallocate (body%flex)
          allocate (body%flex(m, m))
          body%m = m
        end if
        if (.not. allocated(body%b)) allocate (body%b(m))
        call par_bcast_reals(body%flex, m*m, self%host(b))
        call par_bcast_reals(body%b, m, self%host(b))
        rv = [body%prox, solver%mem_bytes, solver%max_rank_mb]
        call par_bcast_reals(rv, 3, self%host(b))
        body%prox = rv(1)
        solver%mem_bytes = rv(2)
        solver%max_rank_mb = rv(3)
        iv(1) = body%rank
        call par_bcast_ints(iv, 1, self%host(b))
        body%rank = iv(1)
        ! the kernel basis of a singular F_a (flex_rank; -1: none), which the harmonic
        ! operator's proximal term needs on rank 0 as much as on the body's host
        iv(1) = -1
        if (allocated(body%kern)) iv(1) = size(body%kern, 2)
        call par_bcast_ints(iv, 1, self%host(b))
        if (iv(1) >= 0) then
          if (.not. (self%mine(b) .and. solver%host)) then
            if (allocated(body%kern)) deallocate (body%kern)
            allocate (body%kern(m, iv(1)))
          end if
          if (iv(1) > 0) call par_bcast_reals(body%kern, m*iv(1), self%host(b))
        end if
      end associate
      call self%err(b)%clear()
    end do
    write (output_unit, '(a,2(f0.1,a))') 'mumps: largest rank''s factorization memory: body 1 ', &
      self%solver(1)%max_rank_mb, ' MB, body 2 ', self%solver(2)%max_rank_mb, ' MB'
  end subroutine share_condensed

  !> The two MUMPS factorizations' memory [MiB].
  subroutine record_factor_memory(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its timing
    run%timing%factor_mb = (self%solver(1)%mem_bytes + self%solver(2)%mem_bytes)/1048576.0_wp
  end subroutine record_factor_memory

  !> Rank 0's contact forces and status to every rank (the others need lam to recover their
  !! body's displacement, and the status to end alike).
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
    do b = 1, 2
      call self%err(b)%clear()
      if (.not. self%mine(b)) cycle
      allocate (uf(run%systems(b)%n))
      uf = 0.0_wp
      call recover_displacement_mumps(run%systems(b), run%bodies(b), self%solver(b), b, &
                                      gather(run%result%lam_body, run%bodies(b)%slots), &
                                      uf, self%err(b))
      if (self%solver(b)%host) call expand(run%systems(b), uf, run%displacement(1:run%systems(b)%ndof, b))
      deallocate (uf)
    end do
    call self%agree_fatal('displacement recovery failed')
    do b = 1, 2
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
  !! at the start of the factorization tells the meshes' and loads' share. Collective.
  subroutine report_ranks(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run
    real(wp) :: pmax, psum, amax
    integer :: where, awhere
    call par_max_real(peak_rss_mb(), pmax, where)
    psum = par_sum_real(peak_rss_mb())
    call par_max_real(self%assembly_peak_mb, amax, awhere)
    write (output_unit, '(a,i0,a,f0.1,a,i0,a,f0.1,a,f0.1)') 'mpi: ranks=', run%ranks, ' peak_rss_max_rank_mb=', pmax, &
      ' max_rank=', where, ' peak_rss_sum_mb=', psum, ' assembly_peak_max_rank_mb=', amax
    flush (output_unit)
  end subroutine report_ranks

  !> Every rank learns the worst status of the bodies' groups; a failure is fatal on all
  !! ranks, with the exit code of its category and the message of the lowest failing rank.
  subroutine agree_fatal(self, what)
    class(mpi_backend_t), intent(inout) :: self
    character(len=*), intent(in) :: what
    integer :: st, b
    character(len=512) :: m1
    st = 0
    m1 = ''
    do b = 2, 1, -1
      if (self%err(b)%failed()) then
        st = exit_code(self%err(b))
        m1 = 'body '//body_label(b)//': '//what//': '//self%err(b)%text()
      end if
    end do
    call par_agree(st, m1)
    if (st /= 0) call fatal(st, trim(m1))
  end subroutine agree_fatal

  !> End the run with its code on every rank: the MUMPS instances freed, MPI finalized.
  subroutine finish(self, run)
    class(mpi_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its exit code
    integer :: b
    do b = 1, 2
      if (self%mine(b)) call mumps_end(self%solver(b))
    end do
    call par_finalize()
    call terminate(run%code)
  end subroutine finish

end module mpi_backend
