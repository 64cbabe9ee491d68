!> One body's stiffness factorized by MUMPS (Debian's MPI build, libdmumps) over a group of
!! ranks, with the body's interface DOFs as Schur variables (doc/batch.md, "MPI and MUMPS"):
!! MUMPS factors the interior and returns S = K_GG - K_GI K_II^-1 K_IG on the group's host,
!! and X = S^-1 = (K^-1)_GG follows by LAPACK (dpotrf/dpotri), as the CHOLMOD path's trailing
!! block. A solve K u = r reduces the right-hand side (ICNTL(26) = 1: r_G - K_GI K_II^-1 r_I),
!! solves the interface part with X, and expands it to the interior (ICNTL(26) = 2).
!! Input is distributed assembled (ICNTL(18) = 3): each rank gives the entries of its
!! share of the cells (assembly%cell_triplets), which MUMPS sums; no rank holds the matrix.
!! Every routine here is collective over the group's communicator. The serial binary
!! compiles mumps_iface_none.f90 (same API, every call an error) instead.
module mumps_iface
  use kinds, only: wp
  use strings, only: i2s
  use lapack, only: dpotrf, dpotri
  use mpi, only: MPI_Bcast, MPI_INTEGER
  use errors, only: error_t, ERR_NUMERICAL
  implicit none (type, external)
  private

  external :: dmumps

  include 'dmumps_struc.h'

  logical, parameter, public :: mumps_built = .true.   !< this binary has MUMPS

  !> One factorized body: the MUMPS instance and, on the host, X = S^-1.
  type, public :: mumps_t
    type(dmumps_struc) :: id                  !< the MUMPS instance
    logical :: alive = .false.                !< initialized (job -1 done)
    logical :: host = .false.                 !< this rank is the group's host (holds X)
    integer :: n = 0                          !< unknowns
    integer :: k = 0                          !< Schur (interface) variables
    real(wp), allocatable :: x(:, :)          !< (k,k) on the host: S^-1 = (K^-1) on the interface DOFs
    real(wp) :: mem_bytes = 0.0_wp            !< factor memory summed over the group's ranks [byte]
    real(wp) :: max_rank_mb = 0.0_wp          !< the largest rank's factorization memory [MiB]
    real(wp) :: factor_mb = 0.0_wp            !< the factor's entries over the group (INFOG(9)) [MiB]
    real(wp) :: rank_factor_mb = 0.0_wp       !< this rank's share of them (INFO(9)) [MiB]
  end type mumps_t

  public :: mumps_schur_factor, mumps_solve, mumps_end

contains

  !> Analyse and factorize K (n x n, symmetric positive definite; each rank gives its
  !! entries of the lower triangle, summed over ranks) with the DOFs schur(:) (1-based) as
  !! Schur variables; on the host, X = S^-1.
  !! err: ERR_NUMERICAL when MUMPS failed or S is not positive definite (which and why).
  subroutine mumps_schur_factor(mt, comm, n, irn, jcn, val, schur, body, err)
    type(mumps_t), intent(inout) :: mt        !< receives the instance
    integer, intent(in) :: comm               !< the group's communicator (host: its rank 0)
    integer, intent(in) :: n                  !< unknowns (same on every rank)
    integer, intent(in) :: irn(:), jcn(:)     !< this rank's entries: rows and columns, 1-based, row >= column
    real(wp), intent(in) :: val(:)            !< this rank's entries [stress]
    integer, intent(in) :: schur(:)           !< (k) host: the Schur variables, 1-based
    integer, intent(in) :: body               !< body number, for messages
    type(error_t), intent(out) :: err         !< the failure, if any
    integer :: j, lap, k, i, cap, st, info
    character(len=32) :: env
    character(len=512) :: msg

    info = 0
    msg = ''
    mt%id%COMM = comm
    mt%id%PAR = 1
    mt%id%SYM = 1
    mt%id%JOB = -1
    call dmumps(mt%id)
    mt%alive = .true.
    nullify (mt%id%IRN_loc, mt%id%JCN_loc, mt%id%A_loc, mt%id%LISTVAR_SCHUR, mt%id%SCHUR, mt%id%RHS, &
             mt%id%REDRHS)
    if (mt%id%INFOG(1) < 0) then
      call fail('initialization')
      return
    end if
    mt%host = mt%id%MYID == 0
    mt%id%ICNTL(1) = -1      ! no MUMPS output: errors are ours to report
    mt%id%ICNTL(2) = -1
    mt%id%ICNTL(3) = -1
    mt%id%ICNTL(4) = 0
    mt%id%ICNTL(18) = 3      ! distributed assembled input: each rank its entries
    ! ROBIN_MUMPS_MAX_MB caps MUMPS's working memory per rank (ICNTL(23), MB): a job's
    ! per-rank share of memory; the tests use a tiny cap to make the factorization fail
    call get_environment_variable('ROBIN_MUMPS_MAX_MB', env, status=st)
    if (st == 0) then
      read (env, *, iostat=st) cap
      if (st == 0 .and. cap > 0) mt%id%ICNTL(23) = cap
    end if
    mt%n = n
    mt%id%N = n
    k = 0
    if (mt%host) k = size(schur)
    call bcast_int(k)
    mt%k = k
    mt%id%NNZ_loc = int(size(val), 8)
    allocate (mt%id%IRN_loc(size(val)), mt%id%JCN_loc(size(val)), mt%id%A_loc(size(val)))
    mt%id%IRN_loc = irn
    mt%id%JCN_loc = jcn
    mt%id%A_loc = val
    if (k > 0) then
      mt%id%ICNTL(19) = 1    ! Schur complement centralized on the host
      mt%id%SIZE_SCHUR = k
      if (mt%host) then
        allocate (mt%id%LISTVAR_SCHUR(k), mt%id%SCHUR(int(k, 8)*k))
        mt%id%LISTVAR_SCHUR = schur
      end if
    end if
    mt%id%JOB = 4            ! analysis + factorization
    call dmumps(mt%id)
    if (mt%id%INFOG(1) < 0) then
      call fail('factorization')
      return
    end if
    mt%mem_bytes = max(0.0_wp, real(mt%id%INFOG(22), wp))*1048576.0_wp   ! MB summed over ranks
    mt%max_rank_mb = real(mt%id%INFOG(21), wp)
    mt%factor_mb = entries_mb(mt%id%INFOG(9))
    mt%rank_factor_mb = entries_mb(mt%id%INFO(9))
    deallocate (mt%id%IRN_loc, mt%id%JCN_loc, mt%id%A_loc)   ! MUMPS has its own copy now
    if (mt%host .and. k > 0) then
      ! S comes as its upper triangle by columns (the lower by rows) in a k x k array, in
      ! the order of schur(:); X = S^-1 by Cholesky (dpotrf/dpotri)
      allocate (mt%x(k, k))
      mt%x = reshape(mt%id%SCHUR, [k, k])
      do j = 1, k
        do i = j + 1, k
          mt%x(i, j) = mt%x(j, i)
        end do
      end do
      call dpotrf('L', k, mt%x, k, lap)
      if (lap == 0) call dpotri('L', k, mt%x, k, lap)
      if (lap /= 0) then
        info = 3
        write (msg, '(a,i0,a,i0,a)') 'the stiffness of body ', body, ' is singular (not held against rigid '// &
          'motion?): its interface Schur complement is not positive definite (LAPACK pivot ', lap, ')'
      else
        do j = 1, k
          do i = j + 1, k
            mt%x(j, i) = mt%x(i, j)
          end do
        end do
      end if
      deallocate (mt%id%SCHUR)
    end if
    call bcast_int(info)
    if (info /= 0 .and. .not. mt%host) write (msg, '(a,i0,a)') 'the stiffness of body ', body, &
      ' is singular (not held against rigid motion?)'
    if (info /= 0) call err%set(ERR_NUMERICAL, msg)

  contains

    !> MUMPS's count of real entries (a negative count is in millions) in MiB.
    real(wp) function entries_mb(c)
      integer, intent(in) :: c
      entries_mb = 8.0_wp*merge(-1.0e6_wp*c, real(c, wp), c < 0)/1048576.0_wp
    end function entries_mb

    subroutine fail(what)
      character(len=*), intent(in) :: what
      call err%set(ERR_NUMERICAL, 'MUMPS '//what//' of body '//i2s(body)//' failed: '// &
                   trim(mumps_error_text(mt%id%INFOG(1), mt%id%INFOG(2), body)))
    end subroutine fail

    subroutine bcast_int(v)
      integer, intent(inout) :: v
      integer :: buf(1), ierr
      buf(1) = v
      call MPI_Bcast(buf, 1, MPI_INTEGER, 0, comm, ierr)
      v = buf(1)
    end subroutine bcast_int

  end subroutine mumps_schur_factor

  !> Solve K u = r in place (r given and u returned on the host): the reduced right-hand
  !! side r_G - K_GI K_II^-1 r_I (ICNTL(26) = 1), u_G = X times it, the interior by
  !! expansion (ICNTL(26) = 2). Collective over the group.
  subroutine mumps_solve(mt, r, body, err)
    type(mumps_t), intent(inout) :: mt          !< factorized body
    real(wp), intent(inout) :: r(:)             !< host: (n) in r [force], out u [length]
    integer, intent(in) :: body                 !< body number, for messages
    type(error_t), intent(out) :: err           !< the failure (ERR_NUMERICAL), if any
    real(wp), allocatable :: ug(:)
    if (mt%host) then
      allocate (mt%id%RHS(mt%n))
      mt%id%RHS = r
      mt%id%NRHS = 1
      mt%id%LRHS = mt%n
    end if
    if (mt%k > 0) then
      if (mt%host) then
        allocate (mt%id%REDRHS(mt%k))
        mt%id%LREDRHS = mt%k
      end if
      mt%id%ICNTL(26) = 1
    else
      mt%id%ICNTL(26) = 0
    end if
    mt%id%JOB = 3
    call dmumps(mt%id)
    if (mt%id%INFOG(1) < 0) then
      call fail()
      return
    end if
    if (mt%k > 0) then
      if (mt%host) then
        ug = matmul(mt%x, mt%id%REDRHS)
        mt%id%REDRHS = ug
      end if
      mt%id%ICNTL(26) = 2
      mt%id%JOB = 3
      call dmumps(mt%id)
      if (mt%id%INFOG(1) < 0) then
        call fail()
        return
      end if
    end if
    if (mt%host) then
      r = mt%id%RHS
      deallocate (mt%id%RHS)
      if (mt%k > 0) deallocate (mt%id%REDRHS)
    end if
  contains
    subroutine fail()
      call err%set(ERR_NUMERICAL, 'MUMPS solve with body '//i2s(body)//' failed: '// &
                   trim(mumps_error_text(mt%id%INFOG(1), mt%id%INFOG(2), body)))
      if (associated(mt%id%RHS)) deallocate (mt%id%RHS)
      if (associated(mt%id%REDRHS)) deallocate (mt%id%REDRHS)
    end subroutine fail
  end subroutine mumps_solve

  !> Free the instance (job -2). Collective over the group.
  subroutine mumps_end(mt)
    type(mumps_t), intent(inout) :: mt
    if (.not. mt%alive) return
    if (associated(mt%id%IRN_loc)) deallocate (mt%id%IRN_loc, mt%id%JCN_loc, mt%id%A_loc)
    if (mt%host) then
      if (associated(mt%id%LISTVAR_SCHUR)) deallocate (mt%id%LISTVAR_SCHUR)
    end if
    mt%id%JOB = -2
    call dmumps(mt%id)
    mt%alive = .false.
  end subroutine mumps_end

  !> A sentence for a MUMPS error code (INFOG(1) < 0, INFOG(2) its detail): MUMPS's status
  !! translated where it is called (the errors of this module's procedures).
  function mumps_error_text(info1, info2, body) result(s)
    integer, intent(in) :: info1, info2, body
    character(len=:), allocatable :: s
    character(len=64) :: c
    write (c, '(a,i0,a,i0,a)') '(INFO(1) = ', info1, ', INFO(2) = ', info2, ')'
    select case (info1)
    case (-10)
      s = 'the stiffness of body '//i2s(body)//' is singular (not held against rigid motion?) '//trim(c)
    case (-19)
      s = 'the working memory cap per rank (ROBIN_MUMPS_MAX_MB, ICNTL(23)) is too small for the factor '//trim(c)
    case (-9, -8, -14, -15, -17, -20)
      s = 'the factor does not fit the memory MUMPS reserved (raise it or use more ranks) '//trim(c)
    case (-13)
      s = 'out of memory in MUMPS (an allocation failed): use more ranks per body or a coarser mesh '//trim(c)
    case (-5, -7)
      s = 'out of memory in the MUMPS analysis: use more ranks per body or a coarser mesh '//trim(c)
    case (-6)
      s = 'the stiffness of body '//i2s(body)//' is structurally singular '//trim(c)
    case default
      s = 'MUMPS error '//trim(c)//' (see the MUMPS user guide, section "Error diagnostics")'
    end select
  end function mumps_error_text

end module mumps_iface
