!> The options of an MPRGP solve (module mprgp), what a solve reports, and the status
!! codes with their names.
module mprgp_options
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use strings, only: sci
  use signals, only: stop_iface
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  public :: mprgp_opts_t, mprgp_stats_t, mprgp_status_name, check_options
  public :: MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_NONFINITE, MPRGP_NOT_SPD, MPRGP_BAD_ARG, MPRGP_STOPPED
  public :: QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST, QP_POLISH

  integer, parameter :: MPRGP_CONVERGED = 0  !< |gP| <= max(rtol |b|, atol) at the true gradient
  integer, parameter :: MPRGP_MAX_IT = 1     !< max_it steps done without convergence
  integer, parameter :: MPRGP_NONFINITE = 2  !< NaN/Inf in the input or during the iteration
  integer, parameter :: MPRGP_NOT_SPD = 3    !< a direction with p'Ap <= 0 was met (A not SPD)
  integer, parameter :: MPRGP_BAD_ARG = 4    !< inconsistent sizes, invalid options or an empty box (ub < lb)
  integer, parameter :: MPRGP_STOPPED = 5    !< opts%stop turned true (a signal): x is the current iterate

  !> The method of a solve (opts%method).
  integer, parameter :: QP_AUTO = 0    !< MPRGP within a budget of steps, then the active-set Newton method
  integer, parameter :: QP_MPRGP = 1   !< MPRGP alone
  integer, parameter :: QP_NEWTON = 2  !< the active-set Newton method alone (module qp_newton; a dense A)
  !> the active-set Newton method within a budget of steps (opts%newton_budget), then MPRGP from
  !! where it stopped: for a warm start whose active set is (nearly) the solution's
  integer, parameter :: QP_NEWTON_FIRST = 3
  !> MPRGP to a tolerance opts%polish_scale times looser, the active-set Newton method from
  !! there within opts%newton_budget steps, then MPRGP from where it stopped: for a warm
  !! start whose active set is still moving, where MPRGP finds the new set at low accuracy
  !! and the Newton method finishes on it exactly
  integer, parameter :: QP_POLISH = 4

  !> Options of an MPRGP solve. Tolerances are in the units of b (for contact: a displacement).
  type :: mprgp_opts_t
    integer :: method = QP_MPRGP     !< QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST or QP_POLISH
    !> QP_AUTO, QP_POLISH: the MPRGP steps allowed before the Newton method takes over (0: the
    !! default budget, max(100, n/16) steps, about the cost of three factorizations of a free
    !! block of n/2 unknowns, (n/2)^3/3 flops each, n/48 products of 2 n^2 flops)
    integer :: auto_budget = 0
    !> QP_NEWTON_FIRST, QP_POLISH: the Newton steps allowed before MPRGP takes over
    integer :: newton_budget = 4
    !> QP_POLISH: MPRGP's first tolerance, as a multiple (>= 1) of rtol and atol
    real(wp) :: polish_scale = 1.0_wp
    real(wp) :: rtol = 1.0e-8_wp     !< stop when |gP| <= max(rtol*|b|, atol)
    real(wp) :: atol = 0.0_wp        !< absolute floor of the stopping test (units of b)
    !> at max_it, a projected gradient (fresh) within the rounding level of A x,
    !! 10 sqrt(n) eps lambda_max max(|x|, |x_0|) (x_0 the projected start), counts as converged
    !! to working precision: a tolerance relative to |b| alone is out of reach when A is
    !! ill-conditioned and x lies along its large eigenvalues (|b| << lambda_max |x|)
    logical :: rounding_floor = .false.
    integer :: max_it = 10000        !< maximum number of CG + expansion + proportioning steps
    real(wp) :: gamma = 1.0_wp       !< proportioning constant Gamma > 0
    real(wp) :: alpha_bar = 0.0_wp   !< expansion step length; <= 0: 1.9/lambda_max (units 1/[A])
    real(wp) :: lambda_max = 0.0_wp  !< > 0: use this largest eigenvalue of A instead of estimating
    integer :: power_its = 20        !< power iterations for the lambda_max estimate
    logical :: use_ax = .false.      !< warm start: the solver's `ax` holds A x at x, no initial product
    logical :: recycle = .false.     !< start with exact line searches along the stored directions `rw` (no product)
    !> With equality rows (the solver's eq_g, eq_e: SMALBE's inner solve) a projected gradient
    !! below the tolerance stops only when it is also below eq_m |eq_g x - eq_e| or the
    !! equality already holds to eq_feas (Dostal's SMALBE-M precision control; SMALBE takes
    !! eq_m as its initial M)
    real(wp) :: eq_m = 0.0_wp        !< M of SMALBE-M (units of b per unit of eq_e)
    real(wp) :: eq_feas = 0.0_wp     !< |eq_g x - eq_e| that counts as feasible (units of eq_e)
    !> SMALBE: |eq_g x - eq_e| <= max(eq_feas, eq_feas_x |x|) counts as feasible, so rows whose
    !! right side vanishes (a body pressed only by a deformation) are judged against the size of x
    real(wp) :: eq_feas_x = 0.0_wp   !< (units of eq_e per unit of x)
    procedure(stop_iface), pointer, nopass :: stop => null()  !< polled every step: stop when true
  end type mprgp_opts_t

  !> What an MPRGP solve did.
  type :: mprgp_stats_t
    integer :: status = MPRGP_BAD_ARG  !< one of the MPRGP_* codes
    integer :: n_cg = 0                !< conjugate gradient steps
    integer :: n_exp = 0               !< expansion steps
    integer :: n_prop = 0              !< proportioning steps
    !> products with A, power iterations included, and the Newton method's factorizations
    !! and solves counted as the products of the same floating-point work (flops / (2 n^2))
    integer :: n_matvec = 0
    integer :: n_newton = 0            !< steps of the active-set Newton method
    integer :: n_factor = 0            !< Cholesky factorizations of a free block (a Newton step on a recurring free set makes none)
    logical :: switched = .false.      !< QP_AUTO: MPRGP used up its budget and the Newton method finished
    !> QP_NEWTON_FIRST, QP_POLISH: the Newton method used up its budget and MPRGP finished
    logical :: fell_back = .false.
    integer :: n_recycled = 0          !< line searches along s and the stored directions that moved x (no product)
    real(wp) :: gp_norm = 0.0_wp       !< |gP| at the returned x (units of b)
    real(wp) :: b_norm = 0.0_wp        !< |b|
    real(wp) :: lambda_max = 0.0_wp    !< lambda_max used (largest of estimate and observed Rayleigh quotients); 0: not needed
    real(wp) :: alpha_bar = 0.0_wp     !< final expansion step length; 0: not needed
    character(len=160) :: message = '' !< one sentence on the outcome
  end type mprgp_stats_t

contains

  !> Name of a status code: 'converged', 'max_it', 'non-finite', 'not SPD', 'bad argument'.
  function mprgp_status_name(status) result(name)
    integer, intent(in) :: status  !< an MPRGP_* code
    character(len=:), allocatable :: name
    select case (status)
    case (MPRGP_CONVERGED)
      name = 'converged'
    case (MPRGP_MAX_IT)
      name = 'max_it'
    case (MPRGP_NONFINITE)
      name = 'non-finite'
    case (MPRGP_NOT_SPD)
      name = 'not SPD'
    case (MPRGP_BAD_ARG)
      name = 'bad argument'
    case (MPRGP_STOPPED)
      name = 'stopped'
    case default
      name = 'unknown status'
    end select
  end function mprgp_status_name

  !> Why the options cannot be used, in err (ERR_INPUT and one sentence naming the option);
  !! no error when they are finite and in range. No deferred-length result: a solve checks
  !! its options on a body loop's thread (doc/developing.md, Conventions).
  subroutine check_options(o, err)
    type(mprgp_opts_t), intent(in) :: o   !< options
    type(error_t), intent(out) :: err     !< the first option out of range
    if (.not. ieee_is_finite(o%rtol)) then
      call err%set(ERR_INPUT, 'opts%rtol is not finite')
      return
    else if (o%rtol < 0.0_wp) then
      call err%set(ERR_INPUT, 'opts%rtol is negative: '//sci(o%rtol, 4))
      return
    end if
    if (.not. ieee_is_finite(o%atol)) then
      call err%set(ERR_INPUT, 'opts%atol is not finite')
      return
    else if (o%atol < 0.0_wp) then
      call err%set(ERR_INPUT, 'opts%atol is negative: '//sci(o%atol, 4))
      return
    end if
    if (o%method < QP_AUTO .or. o%method > QP_POLISH) then
      call err%set(ERR_INPUT, 'opts%method is not QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST or QP_POLISH')
      return
    end if
    if (o%auto_budget < 0) then
      call err%set(ERR_INPUT, 'opts%auto_budget is negative')
      return
    end if
    if (.not. (o%polish_scale >= 1.0_wp .and. ieee_is_finite(o%polish_scale))) then
      call err%set(ERR_INPUT, 'opts%polish_scale is not a finite number >= 1: '//sci(o%polish_scale, 4))
      return
    end if
    if (o%newton_budget < 0) then
      call err%set(ERR_INPUT, 'opts%newton_budget is negative')
      return
    end if
    if (o%max_it < 0) then
      call err%set(ERR_INPUT, 'opts%max_it is negative')
      return
    end if
    if (.not. ieee_is_finite(o%gamma)) then
      call err%set(ERR_INPUT, 'opts%gamma is not finite')
      return
    else if (o%gamma <= 0.0_wp) then
      call err%set(ERR_INPUT, 'opts%gamma must be positive: '//sci(o%gamma, 4))
      return
    end if
    if (.not. (ieee_is_finite(o%alpha_bar) .and. ieee_is_finite(o%lambda_max))) then
      call err%set(ERR_INPUT, 'opts%alpha_bar or opts%lambda_max is not finite')
      return
    end if
    if (o%alpha_bar <= 0.0_wp .and. o%lambda_max <= 0.0_wp .and. o%power_its < 1) then
      call err%set(ERR_INPUT, 'opts%power_its must be >= 1 when neither alpha_bar nor lambda_max is given')
      return
    end if
  end subroutine check_options

end module mprgp_options
