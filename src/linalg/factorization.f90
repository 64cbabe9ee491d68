!> A body's stiffness factorization as one object, whatever library made it: the abstract
!! `factor_t` with its CHOLMOD, banded and MUMPS extensions, and `new_factor`, the one place
!! where the deck's `factorization` picks the extension. The condensed body
!! (condense%body_condensed_t) owns one on both paths, serial and MPI, and reaches it only
!! through these methods:
!!   factorize          K = L L' (or MUMPS's LDL'), the interface DOFs ordered last / Schur
!!   solve              K u = r in place
!!   interface_inverse  X = (K^-1) on the interface DOFs (the condensation hook: CHOLMOD's
!!                      trailing block of L, unit solves for the banded factor, S^-1 for MUMPS)
!!   rows_flexibility   F = B X B' for sparse rows B on those DOFs (CHOLMOD: from the trailing
!!                      block without X; the others: X, then flex_product)
!!   free, summary      release; one line of statistics (`stats` holds the numbers)
!! Every failure is an `error_t` (module errors): a solve or an inverse without a valid
!! factorization, a matrix that is not positive definite, a library's status, never a NaN.
!!
!! A MUMPS factor is collective over its group of ranks (its `comm`): `factorize`, `solve`
!! and `interface_inverse` are called on every rank of the group, and only the group's host
!! gives and receives vectors (`holds_result`); the others pass empty ones. A CHOLMOD or
!! banded factor is on one rank, which holds everything.
module factorization
  use kinds, only: wp, ip, i8
  use space, only: NDIM
  use config, only: factor_cfg_t, FACTOR_BANDED, FACTOR_MUMPS, ORDER_AMD, ORDER_NATURAL, ORDER_ND
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN, ORD_NODES
  use mumps_iface, only: mumps_t, mumps_schur_factor, mumps_solve, mumps_end
  use errors, only: error_t, ERR_NUMERICAL, ERR_MEMORY
  use strings, only: i2s
  implicit none (type, external)
  private

  public :: factor_t, chol_factor_t, cholmod_factor_t, banded_factor_t, mumps_factor_t, factor_stats_t, new_factor
  public :: flex_product

  !> What a factorization cost and holds.
  type :: factor_stats_t
    real(wp) :: t_analyze = 0.0_wp        !< ordering + symbolic analysis wall time [s]
    real(wp) :: t_factor = 0.0_wp         !< numeric factorization wall time [s]
    integer(i8) :: nnz_factor = 0         !< nonzeros in L (0: not known)
    real(wp) :: flops = 0.0_wp            !< factorization flop count (0: not known)
    !> CHOLMOD: the dense-kernel tiles its numeric factorization ran (blas_tiles.c; 0 for
    !! the other factorizations)
    real(wp) :: tiles = 0.0_wp
    real(wp) :: mem_bytes = 0.0_wp        !< the factor's memory (MUMPS: summed over the group's ranks) [byte]
    real(wp) :: max_rank_mb = 0.0_wp      !< MUMPS: the largest rank's factorization memory [MiB]
    real(wp) :: factor_mb = 0.0_wp        !< MUMPS: the factor's entries over the group (INFOG(9)) [MiB]
    real(wp) :: rank_factor_mb = 0.0_wp   !< MUMPS: this rank's share of them (INFO(9)) [MiB]
  end type factor_stats_t

  !> One factorization of one body's stiffness K (n x n, symmetric positive definite).
  type, abstract :: factor_t
    integer :: n = 0                      !< matrix order (0: not factorized)
    integer :: body = 0                   !< the body, for messages
    type(factor_stats_t) :: stats         !< cost and size
    !> the factor lives on a group of ranks, its results on the host only (the condensed
    !! body then keeps no K^-1 f of its own)
    logical :: distributed = .false.
  contains
    !> Factorize K with the DOFs `last` ordered last (the interface).
    procedure(factorize_i), deferred :: factorize
    !> Solve K u = r in place.
    procedure(solve_i), deferred :: solve
    !> X = (K^-1)(idx, idx) for the interface DOFs idx (those given to factorize as `last`).
    procedure(inverse_i), deferred :: interface_inverse
    !> F = B X B' for sparse rows B on the interface DOFs (X as interface_inverse's).
    procedure :: rows_flexibility => factor_rows_flexibility
    !> True when rows_flexibility on these DOFs reads the factor only, so that a solve may run
    !! beside it on another thread (default: false, it solves).
    procedure :: flexibility_beside_solve => factor_flexibility_beside_solve
    !> Release the factorization.
    procedure(free_i), deferred :: free
    !> One line: method, sizes, times, memory.
    procedure(summary_i), deferred :: summary
    !> True where the results are: everywhere but on a MUMPS group's other ranks.
    procedure :: holds_result => factor_holds_result
    !> True when factorize wants the order of the DOFs before `last` (interior_perm).
    procedure :: wants_interior_order => factor_wants_interior_order
  end type factor_t

  abstract interface
    !> K as full symmetric CSC (CHOLMOD, banded: colptr, rowind, val, 0-based) or as this
    !! rank's share of triplets of the lower triangle (MUMPS: irn, jcn, tval, 1-based, summed
    !! over the ranks); interior_perm: the order of the DOFs not in `last`, when wanted.
    subroutine factorize_i(self, n, last, err, colptr, rowind, val, interior_perm, irn, jcn, tval)
      import :: factor_t, error_t, ip, wp
      class(factor_t), intent(inout) :: self
      integer, intent(in) :: n
      integer, intent(in) :: last(:)
      type(error_t), intent(out) :: err
      integer(ip), intent(in), optional :: colptr(:), rowind(:)
      real(wp), intent(in), optional :: val(:)
      integer, intent(in), optional :: interior_perm(:)
      integer, intent(in), optional :: irn(:), jcn(:)
      real(wp), intent(in), optional :: tval(:)
    end subroutine factorize_i
    subroutine solve_i(self, b, err)
      import :: factor_t, error_t, wp
      class(factor_t), intent(inout) :: self
      real(wp), intent(inout), contiguous :: b(:)
      type(error_t), intent(out) :: err
    end subroutine solve_i
    subroutine inverse_i(self, idx, x, err)
      import :: factor_t, error_t, wp
      class(factor_t), intent(inout) :: self
      integer, intent(in) :: idx(:)
      real(wp), intent(out) :: x(:, :)
      type(error_t), intent(out) :: err
    end subroutine inverse_i
    subroutine free_i(self)
      import :: factor_t
      class(factor_t), intent(inout) :: self
    end subroutine free_i
    function summary_i(self) result(line)
      import :: factor_t
      class(factor_t), intent(in) :: self
      character(len=:), allocatable :: line
    end function summary_i
  end interface

  !> A Cholesky factor of module cholesky (CHOLMOD or banded) on one rank.
  type, abstract, extends(factor_t) :: chol_factor_t
    type(chol_t) :: chol                  !< the factorization
    integer :: method = FACT_CHOLMOD      !< FACT_CHOLMOD or FACT_BANDED
    integer :: ordering = ORD_METIS       !< ORD_* (CHOLMOD)
  contains
    procedure :: factorize => chol_factorize
    procedure :: solve => chol_solve
    procedure :: interface_inverse => chol_inverse
    procedure :: rows_flexibility => chol_rows_flexibility
    procedure :: flexibility_beside_solve => chol_flexibility_beside_solve
    procedure :: free => chol_free
    procedure :: summary => chol_summary
    procedure :: wants_interior_order => chol_wants_interior_order
  end type chol_factor_t

  !> CHOLMOD supernodal L L' with the interface last: X from the trailing block of L.
  type, extends(chol_factor_t) :: cholmod_factor_t
  end type cholmod_factor_t

  !> Reverse Cuthill-McKee and LAPACK's band Cholesky: X by unit solves.
  type, extends(chol_factor_t) :: banded_factor_t
  end type banded_factor_t

  !> MUMPS over the body's group of ranks with the interface DOFs as Schur variables
  !! (module mumps_iface): X = S^-1 on the host.
  type, extends(factor_t) :: mumps_factor_t
    type(mumps_t) :: mt                   !< the MUMPS instance
    integer :: comm = 0                   !< the group's communicator
  contains
    procedure :: factorize => mumps_factorize
    procedure :: solve => mumps_factor_solve
    procedure :: interface_inverse => mumps_inverse
    procedure :: free => mumps_free
    procedure :: summary => mumps_summary
    procedure :: holds_result => mumps_holds_result
  end type mumps_factor_t

contains

  !> The factor the deck's setting names, not yet factorized: CHOLMOD with its ordering
  !! (ordering='nd': in the plane the caller's interior order, a solid body's by METIS on its
  !! node graph; the interface last), banded, or MUMPS over the group `comm` (default: 0).
  !! The one place where the deck's choices (config's FACTOR_* and ORDER_*) become linalg's
  !! codes (cholesky's FACT_*, cholmod_iface's ORD_*): the deck's lists are what a user may
  !! write, linalg's what a factorization can do (MUMPS is no chol_t; 'nd' is ORD_GIVEN or
  !! ORD_NODES by the dimension), and config, upstream of linalg, cannot use linalg's.
  subroutine new_factor(fc, body_id, fac, comm)
    type(factor_cfg_t), intent(in) :: fc                  !< factorization and ordering
    integer, intent(in) :: body_id                        !< the body's number, for messages
    class(factor_t), allocatable, intent(out) :: fac      !< the new factor
    integer, intent(in), optional :: comm                 !< MUMPS: the body's group of ranks
    select case (fc%factorization)
    case (FACTOR_MUMPS)
      allocate (mumps_factor_t :: fac)
      select type (fac)
      type is (mumps_factor_t)
        if (present(comm)) fac%comm = comm
        fac%distributed = .true.
      end select
    case (FACTOR_BANDED)
      allocate (banded_factor_t :: fac)
      select type (fac)
      type is (banded_factor_t)
        fac%method = FACT_BANDED
      end select
    case default
      allocate (cholmod_factor_t :: fac)
      select type (fac)
      type is (cholmod_factor_t)
        fac%method = FACT_CHOLMOD
        select case (fc%ordering)
        case (ORDER_AMD)
          fac%ordering = ORD_AMD
        case (ORDER_NATURAL)
          fac%ordering = ORD_NATURAL
        case (ORDER_ND)     ! the geometric dissection is the plane's; a solid body: METIS on its nodes
          fac%ordering = merge(ORD_GIVEN, ORD_NODES, NDIM == 2)
        case default
          fac%ordering = ORD_METIS
        end select
      end select
    end select
    fac%body = body_id
  end subroutine new_factor

  !> A factor on one rank holds its results (a distributed one overrides this).
  logical function factor_holds_result(self) result(yes)
    class(factor_t), intent(in) :: self
    yes = .not. self%distributed
  end function factor_holds_result

  !> No interior order wanted.
  logical function factor_wants_interior_order(self) result(yes)
    class(factor_t), intent(in) :: self
    yes = .false.
  end function factor_wants_interior_order

  ! ---- CHOLMOD and banded -------------------------------------------------------------

  !> CHOLMOD with ORD_GIVEN takes the caller's interior order.
  logical function chol_wants_interior_order(self) result(yes)
    class(chol_factor_t), intent(in) :: self
    yes = self%method == FACT_CHOLMOD .and. self%ordering == ORD_GIVEN
  end function chol_wants_interior_order

  !> Factorize the full symmetric CSC K (cholesky%chol_factor), `last` ordered last.
  subroutine chol_factorize(self, n, last, err, colptr, rowind, val, interior_perm, irn, jcn, tval)
    class(chol_factor_t), intent(inout) :: self
    integer, intent(in) :: n                              !< matrix order
    integer, intent(in) :: last(:)                        !< 1-based DOFs ordered last
    type(error_t), intent(out) :: err                     !< the failure, if any
    integer(ip), intent(in), optional :: colptr(:), rowind(:)   !< K (CSC, 0-based)
    real(wp), intent(in), optional :: val(:)              !< its values
    integer, intent(in), optional :: interior_perm(:)     !< ORD_GIVEN: the order of the other DOFs
    integer, intent(in), optional :: irn(:), jcn(:)       !< not used (MUMPS's input)
    real(wp), intent(in), optional :: tval(:)             !< not used (MUMPS's input)
    self%n = 0
    if (.not. (present(colptr) .and. present(rowind) .and. present(val))) then
      call err%set(ERR_NUMERICAL, 'Cholesky: the factorization needs the stiffness in CSC form.')
      return
    end if
    if (present(irn) .or. present(jcn) .or. present(tval)) then
      call err%set(ERR_NUMERICAL, 'Cholesky: triplet input is MUMPS''s, not a Cholesky factor''s.')
      return
    end if
    call self%chol%factor(n, colptr, rowind, val, self%method, self%ordering, err, last=last, &
                          interior_perm=interior_perm)
    if (err%failed()) return
    self%n = n
    self%stats%t_analyze = self%chol%t_analyze
    self%stats%t_factor = self%chol%t_factor
    self%stats%nnz_factor = self%chol%nnz_factor
    self%stats%flops = self%chol%flops
    self%stats%tiles = real(self%chol%tiles, wp)
    self%stats%mem_bytes = real(self%chol%mem_bytes, wp)
  end subroutine chol_factorize

  !> K u = b in place; err without a valid factorization or on a library failure.
  subroutine chol_solve(self, b, err)
    class(chol_factor_t), intent(inout) :: self
    real(wp), intent(inout), contiguous :: b(:)   !< right-hand side in, solution out
    type(error_t), intent(out) :: err             !< the failure, if any
    call self%chol%solve(b, err)
  end subroutine chol_solve

  !> X = (K^-1)(idx, idx): CHOLMOD's trailing block when idx were ordered last, unit
  !! solves otherwise (cholesky%chol_flexibility).
  subroutine chol_inverse(self, idx, x, err)
    class(chol_factor_t), intent(inout) :: self
    integer, intent(in) :: idx(:)                 !< 1-based interface DOFs
    real(wp), intent(out) :: x(:, :)              !< (k,k) (K^-1)(idx, idx)
    type(error_t), intent(out) :: err             !< the failure, if any
    call self%chol%flexibility(idx, spread(1.0_wp, 1, size(idx)), x, err)
  end subroutine chol_inverse

  !> F = B X B', X = (K^-1)(idx, idx) by interface_inverse, then flex_product. Called where
  !! the results are (holds_result).
  subroutine factor_rows_flexibility(self, idx, bptr, bpos, bval, flex, err)
    class(factor_t), intent(inout) :: self
    integer, intent(in) :: idx(:)                 !< 1-based interface DOFs (the columns of B)
    integer, intent(in) :: bptr(:)                !< (m+1) row starts in bpos, bval
    integer, intent(in) :: bpos(:)                !< columns of B's entries (into idx)
    real(wp), intent(in) :: bval(:)               !< B's entries
    real(wp), intent(out) :: flex(:, :)           !< (m,m) B X B'
    type(error_t), intent(out) :: err             !< the failure, if any
    real(wp), allocatable :: x(:, :)
    integer :: st
    allocate (x(size(idx), size(idx)), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'out of memory for the interface block of K^-1')
      return
    end if
    if (size(idx) > 0) call self%interface_inverse(idx, x, err)
    if (err%failed()) return
    call flex_product(x, bptr, bpos, bval, flex)
  end subroutine factor_rows_flexibility

  !> False: a factor's own rows_flexibility solves with it.
  logical function factor_flexibility_beside_solve(self, idx) result(yes)
    class(factor_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based interface DOFs
    yes = .false.
  end function factor_flexibility_beside_solve

  !> True when F comes from CHOLMOD's trailing block (cholesky%holds_block).
  logical function chol_flexibility_beside_solve(self, idx) result(yes)
    class(chol_factor_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based interface DOFs
    yes = self%chol%holds_block(idx)
  end function chol_flexibility_beside_solve

  !> F = B X B' from CHOLMOD's trailing block (cholesky%chol_row_flexibility), else as
  !! every factor does (X, then flex_product).
  subroutine chol_rows_flexibility(self, idx, bptr, bpos, bval, flex, err)
    class(chol_factor_t), intent(inout) :: self
    integer, intent(in) :: idx(:)                 !< 1-based interface DOFs (the columns of B)
    integer, intent(in) :: bptr(:)                !< (m+1) row starts in bpos, bval
    integer, intent(in) :: bpos(:)                !< columns of B's entries (into idx)
    real(wp), intent(in) :: bval(:)               !< B's entries
    real(wp), intent(out) :: flex(:, :)           !< (m,m) B X B'
    type(error_t), intent(out) :: err             !< the failure, if any
    logical :: used
    call self%chol%row_flexibility(idx, bptr, bpos, bval, flex, err, used)
    if (.not. used) call factor_rows_flexibility(self, idx, bptr, bpos, bval, flex, err)
  end subroutine chol_rows_flexibility

  !> F = B X B' from X = (K^-1) on the interface DOFs, over B's nnz entries, two ways: entry
  !! pairs of every two rows (nnz^2 products: rows of one or a few entries, a slave's, and
  !! every plane body's), or, when that would cost over four times as much, Y = X B' and then
  !! B Y ((k + m) nnz: a solid master's rows, each over the DOFs of every master node its
  !! slave node's support meets), symmetrized.
  subroutine flex_product(x, bptr, bpos, bval, flex)
    real(wp), intent(in) :: x(:, :)               !< (k,k) (K^-1) on the interface DOFs
    integer, intent(in) :: bptr(:)                !< (m+1) row starts in bpos, bval
    integer, intent(in) :: bpos(:)                !< columns of B's entries (into x)
    real(wp), intent(in) :: bval(:)               !< B's entries
    real(wp), intent(out) :: flex(:, :)           !< (m,m) B X B'
    integer :: i, j, e, f, k, m, nnz
    real(wp) :: acc
    real(wp), allocatable :: y(:, :)
    m = size(bptr) - 1
    k = size(x, 1)
    nnz = size(bval)
    if (m > 0) flex = 0.0_wp
    if (m == 0 .or. k == 0) return
    if (nnz <= 4*(k + m)) then
      do j = 1, m
        do i = 1, m
          acc = 0.0_wp
          do f = bptr(j), bptr(j + 1) - 1
            do e = bptr(i), bptr(i + 1) - 1
              acc = acc + (bval(e)*bval(f))*x(bpos(e), bpos(f))
            end do
          end do
          flex(i, j) = acc
        end do
      end do
    else
      allocate (y(k, m))
      y = 0.0_wp
      do j = 1, m
        do f = bptr(j), bptr(j + 1) - 1
          y(:, j) = y(:, j) + bval(f)*x(:, bpos(f))
        end do
      end do
      do j = 1, m
        do i = 1, m
          acc = 0.0_wp
          do e = bptr(i), bptr(i + 1) - 1
            acc = acc + bval(e)*y(bpos(e), j)
          end do
          flex(i, j) = acc
        end do
      end do
      ! the same number from either side: F symmetric to the last bit
      flex = 0.5_wp*(flex + transpose(flex))
    end if
  end subroutine flex_product

  !> Release the factorization.
  subroutine chol_free(self)
    class(chol_factor_t), intent(inout) :: self
    call self%chol%free()
    self%n = 0
    self%stats = factor_stats_t()
  end subroutine chol_free

  !> cholesky%chol_summary's line.
  function chol_summary(self) result(line)
    class(chol_factor_t), intent(in) :: self
    character(len=:), allocatable :: line
    line = self%chol%summary()
  end function chol_summary

  ! ---- MUMPS ----------------------------------------------------------------------------

  !> Analyse and factorize this rank's share of K over the group, `last` as Schur
  !! variables (collective); on the host, X = S^-1.
  subroutine mumps_factorize(self, n, last, err, colptr, rowind, val, interior_perm, irn, jcn, tval)
    class(mumps_factor_t), intent(inout) :: self
    integer, intent(in) :: n                              !< matrix order (every rank)
    integer, intent(in) :: last(:)                        !< host: the Schur variables, 1-based
    type(error_t), intent(out) :: err                     !< the failure, if any
    integer(ip), intent(in), optional :: colptr(:), rowind(:)   !< not used (a Cholesky factor's input)
    real(wp), intent(in), optional :: val(:)              !< not used
    integer, intent(in), optional :: interior_perm(:)     !< not used (MUMPS orders itself)
    integer, intent(in), optional :: irn(:), jcn(:)       !< this rank's entries, 1-based, row >= column
    real(wp), intent(in), optional :: tval(:)             !< their values [stress]
    self%n = 0
    if (.not. (present(irn) .and. present(jcn) .and. present(tval))) then
      call err%set(ERR_NUMERICAL, 'MUMPS: the factorization of body '//i2s(self%body)// &
                   ' needs its share of the stiffness as triplets.')
      return
    end if
    if (present(colptr) .or. present(rowind) .or. present(val) .or. present(interior_perm)) then
      call err%set(ERR_NUMERICAL, 'MUMPS: CSC input and a given order are a Cholesky factor''s, not MUMPS''s.')
      return
    end if
    call mumps_schur_factor(self%mt, self%comm, n, irn, jcn, tval, last, self%body, err)
    self%stats%mem_bytes = self%mt%mem_bytes
    self%stats%max_rank_mb = self%mt%max_rank_mb
    self%stats%factor_mb = self%mt%factor_mb
    self%stats%rank_factor_mb = self%mt%rank_factor_mb
    if (err%failed()) return
    self%n = n
  end subroutine mumps_factorize

  !> K u = b in place on the host (the other ranks pass an empty b); collective.
  subroutine mumps_factor_solve(self, b, err)
    class(mumps_factor_t), intent(inout) :: self
    real(wp), intent(inout), contiguous :: b(:)   !< host: right-hand side in, solution out
    type(error_t), intent(out) :: err             !< the failure, if any
    if (self%n <= 0) then
      call err%set(ERR_NUMERICAL, 'MUMPS: solve called without a valid factorization of body '// &
                   i2s(self%body)//'.')
      return
    end if
    call mumps_solve(self%mt, b, self%body, err)
  end subroutine mumps_factor_solve

  !> X = S^-1 on the host (the Schur variables are the interface DOFs, in the order given
  !! to factorize: idx must be them).
  subroutine mumps_inverse(self, idx, x, err)
    class(mumps_factor_t), intent(inout) :: self
    integer, intent(in) :: idx(:)                 !< the interface DOFs (as given to factorize)
    real(wp), intent(out) :: x(:, :)              !< host: (k,k) S^-1
    type(error_t), intent(out) :: err             !< the failure, if any
    character(len=120) :: emsg
    if (self%n <= 0 .or. .not. allocated(self%mt%x)) then
      call err%set(ERR_NUMERICAL, 'MUMPS: the interface inverse of body '//i2s(self%body)// &
                   ' was asked for without a valid factorization.')
      return
    end if
    if (size(self%mt%x, 1) /= size(idx) .or. size(x, 1) /= size(idx) .or. size(x, 2) /= size(idx)) then
      write (emsg, '(a,i0,a,i0,a)') 'MUMPS: the interface inverse has ', size(self%mt%x, 1), &
        ' Schur variables, not ', size(idx), '.'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    x = self%mt%x
  end subroutine mumps_inverse

  !> Free the instance (collective).
  subroutine mumps_free(self)
    class(mumps_factor_t), intent(inout) :: self
    call mumps_end(self%mt)
    self%n = 0
  end subroutine mumps_free

  !> One line: MUMPS, order, Schur variables, memory.
  function mumps_summary(self) result(line)
    class(mumps_factor_t), intent(in) :: self
    character(len=:), allocatable :: line
    character(len=200) :: buf
    write (buf, '(a,i0,a,i0,a,f0.1,a,f0.1,a)') 'mumps n=', self%n, ' schur=', self%mt%k, ' mem=', &
      self%stats%mem_bytes/2.0_wp**20, 'MiB max_rank=', self%stats%max_rank_mb, 'MiB'
    line = trim(buf)
  end function mumps_summary

  !> Only the group's host holds the results.
  logical function mumps_holds_result(self) result(yes)
    class(mumps_factor_t), intent(in) :: self
    yes = self%mt%host
  end function mumps_holds_result

end module factorization
