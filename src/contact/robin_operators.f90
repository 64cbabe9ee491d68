!> The Robin operators of the outer iteration (doc/method.md, "Method as implemented"):
!! body 1's obstacle moves by S_1 d, body 2's by -S_2 d (d = lam_1 - lam_2).
!! 'steklov' (the paper's: S_1 = F_2, S_2 = F_1), 'constant' (S_1 = S_2 = alpha M^-1) and
!! 'harmonic' (S_1 = S_2 = 2 F_1 (F_1+F_2)^-1 F_2) extend one abstract type; they differ in
!! the correction itself, the inner tolerance, the bound of lambda_max(F_a) the subproblems
!! use, and the proximal term of a body with a singular F_a. `new_robin_operator` is the
!! one place that picks the operator from the decoded setting (config's ROBIN_*).
module robin_operators
  use kinds, only: wp
  use config, only: solver_cfg_t, ROBIN_CONSTANT, ROBIN_HARMONIC
  use linop, only: dense_op_t, dense_op_init
  use lapack, only: dgemm, dposv, dgesv
  use mprgp, only: lambda_max_estimate
  use condense, only: interface_t, body_condensed_t
  use contact_common, only: other_body
  use errors, only: error_t, ERR_NUMERICAL
  implicit none (type, external)
  private

  integer, parameter :: POWER_ITS = 10   !< power iterations for each body's lambda_max (harmonic operator)

  !> A Robin operator: the correction of the obstacles and what goes with it.
  type, abstract, public :: robin_operator_t
  contains
    !> Build the correction once, before the outer loop.
    procedure(setup_iface), deferred :: setup
    !> corr(:, 1) = S_1 d, corr(:, 2) = S_2 d; count grows by the Hessian-sized products.
    procedure(apply_iface), deferred :: apply
    !> The inner tolerance of outer iteration `it` (default: follows the outer progress).
    procedure :: inner_tolerance => progress_tolerance
    !> A bound of lambda_max(F_a) for MPRGP (default: the row-sum norm, no product).
    procedure :: body_lambda_max => row_sum_bound
    !> The proximal term Pi_a of a body whose F_a is singular (default: the other body's F).
    procedure :: proximal_term => other_flexibility
  end type robin_operator_t

  abstract interface
    !> Build the correction; err (ERR_NUMERICAL) when it cannot be built.
    subroutine setup_iface(self, solver, contact_line, bodies, flexibility, err)
      import :: robin_operator_t, solver_cfg_t, interface_t, body_condensed_t, dense_op_t, error_t
      class(robin_operator_t), intent(inout) :: self
      type(solver_cfg_t), intent(in) :: solver
      type(interface_t), intent(in) :: contact_line
      type(body_condensed_t), intent(in) :: bodies(2)
      type(dense_op_t), target, intent(in) :: flexibility(2)    !< F_a as operators (kept by reference)
      type(error_t), intent(out) :: err
    end subroutine setup_iface

    !> corr(:, 1) = S_1 d, corr(:, 2) = S_2 d.
    subroutine apply_iface(self, d, corr, count)
      import :: robin_operator_t, wp
      class(robin_operator_t), intent(inout) :: self
      real(wp), intent(in) :: d(:)
      real(wp), intent(out) :: corr(:, :)
      integer, intent(inout) :: count
    end subroutine apply_iface
  end interface

  !> 'steklov': each obstacle corrected by the other body's flexibility (a floating body's
  !! on self-equilibrated forces only: `projected_flex`).
  type, extends(robin_operator_t), public :: steklov_operator_t
    type(dense_op_t), pointer :: flexibility(:) => null()   !< F_a (the subproblems' operators)
    type(dense_op_t) :: projected(2)             !< P_a F_a P_a of a floating body (n = 0: none)
  contains
    procedure :: setup => steklov_setup
    procedure :: apply => steklov_apply
  end type steklov_operator_t

  !> 'constant': alpha M^-1, M the tributary lengths.
  type, extends(robin_operator_t), public :: constant_operator_t
    real(wp) :: alpha = 0.0_wp               !< Robin parameter [length/stress]
    real(wp), allocatable :: w(:)            !< (m) tributary lengths [length]
  contains
    procedure :: setup => constant_setup
    procedure :: apply => constant_apply
  end type constant_operator_t

  !> 'harmonic': S = 2 F_1 (F_1+F_2)^-1 F_2 for both obstacles (contrast-robust).
  type, extends(robin_operator_t), public :: harmonic_operator_t
    type(dense_op_t) :: s                    !< S, formed once
  contains
    procedure :: setup => harmonic_setup
    procedure :: apply => harmonic_apply
    procedure :: inner_tolerance => harmonic_tolerance
    procedure :: body_lambda_max => power_estimate
    procedure :: proximal_term => kernel_proximal
  end type harmonic_operator_t

  public :: new_robin_operator

contains

  !> The Robin operator of a ROBIN_* code (config), not yet set up.
  function new_robin_operator(kind) result(op)
    integer, intent(in) :: kind                      !< ROBIN_*
    class(robin_operator_t), allocatable :: op
    select case (kind)
    case (ROBIN_CONSTANT)
      allocate (constant_operator_t :: op)
    case (ROBIN_HARMONIC)
      allocate (harmonic_operator_t :: op)
    case default
      allocate (steklov_operator_t :: op)
    end select
  end function new_robin_operator

  ! ---- defaults --------------------------------------------------------------------------

  !> The inner tolerance following the outer progress, min(increment, residual) of the
  !! previous iteration, times inner_factor, clamped to [inner_rtol_min, inner_rtol_max].
  real(wp) function progress_tolerance(self, solver, it, m, progress, lmax) result(rtol_in)
    class(robin_operator_t), intent(in) :: self
    type(solver_cfg_t), intent(in) :: solver       !< solver settings
    integer, intent(in) :: it                      !< outer iteration
    integer, intent(in) :: m                       !< contact nodes
    real(wp), intent(in) :: progress               !< min(increment, residual) of iteration it - 1
    real(wp), intent(in) :: lmax(2)                !< bounds of lambda_max(F_a)
    if (it == 1) then
      rtol_in = solver%inner_rtol_max
    else
      rtol_in = min(solver%inner_rtol_max, max(solver%inner_rtol_min, solver%inner_factor*progress))
    end if
  end function progress_tolerance

  !> The row-sum norm |F_a|_inf, an upper bound of lambda_max for a symmetric matrix (so
  !! alpha_bar = 1.9/|F_a|_inf is admissible without MPRGP's guard): one pass over F_a, no
  !! product (nmv = 0).
  real(wp) function row_sum_bound(self, flexibility, flex, nmv) result(lmax)
    class(robin_operator_t), intent(in) :: self
    type(dense_op_t), intent(inout) :: flexibility     !< F_a as an operator
    real(wp), intent(in) :: flex(:, :)                 !< F_a
    integer, intent(out) :: nmv                        !< products with F_a taken
    lmax = maxval(sum(abs(flex), dim=1))
    nmv = 0
  end function row_sum_bound

  !> Pi_a = F_o, the other body's flexibility: F_a + F_o is the monolithic Hessian, definite
  !! (doc/method.md, "Non-matching and curved contact surfaces: dual mortar").
  subroutine other_flexibility(self, bodies, a, p)
    class(robin_operator_t), intent(in) :: self
    type(body_condensed_t), intent(in) :: bodies(2)    !< condensed bodies
    integer, intent(in) :: a                           !< the body with a singular F_a
    real(wp), intent(out) :: p(:, :)                   !< Pi_a
    p = bodies(other_body(a))%flex
  end subroutine other_flexibility

  ! ---- steklov ---------------------------------------------------------------------------

  subroutine steklov_setup(self, solver, contact_line, bodies, flexibility, err)
    class(steklov_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(2)
    type(dense_op_t), target, intent(in) :: flexibility(2)
    type(error_t), intent(out) :: err
    integer :: a
    do a = 1, 2
      self%projected(a)%n = 0
      if (bodies(a)%nrig > 0 .and. contact_line%m > 0) &
        call dense_op_init(self%projected(a), projected_flex(bodies(a)))
    end do
    self%flexibility => flexibility
  end subroutine steklov_setup

  subroutine steklov_apply(self, d, corr, count)
    class(steklov_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    if (self%projected(2)%n > 0) then
      call self%projected(2)%apply(d, corr(:, 1))
    else
      call self%flexibility(2)%apply(d, corr(:, 1))
    end if
    if (self%projected(1)%n > 0) then
      call self%projected(1)%apply(d, corr(:, 2))
    else
      call self%flexibility(1)%apply(d, corr(:, 2))
    end if
    count = count + 2
  end subroutine steklov_apply

  !> P F_a P with P = I - G_a'(G_a G_a')^-1 G_a, the orthogonal projector on the forces that
  !! G_a sees as balanced: a floating body's F_a depends on its fixing DOFs by terms in G_a'
  !! (rigid motions), its response to a self-equilibrated force does not
  !! (doc/method.md, "Bodies held only by contact").
  function projected_flex(body) result(pf)
    type(body_condensed_t), intent(in) :: body
    real(wp), allocatable :: pf(:, :), q(:, :), gg(:, :), y(:, :)
    integer :: m, r, info
    m = body%m
    r = body%nrig
    allocate (pf(m, m), q(r, m), gg(r, r), y(m, m))
    ! q = (G G')^-1 G, so that P x = x - G' (q x)
    gg = matmul(body%rg, transpose(body%rg))
    q = body%rg
    call dposv('U', r, m, gg, r, q, r, info)
    ! y = P F = F - G' (q F);  pf = y P = y - (y q') G
    y = body%flex - matmul(transpose(body%rg), matmul(q, body%flex))
    pf = y - matmul(matmul(y, transpose(q)), body%rg)
    pf = 0.5_wp*(pf + transpose(pf))
  end function projected_flex

  ! ---- constant --------------------------------------------------------------------------

  subroutine constant_setup(self, solver, contact_line, bodies, flexibility, err)
    class(constant_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(2)
    type(dense_op_t), target, intent(in) :: flexibility(2)
    type(error_t), intent(out) :: err
    self%alpha = solver%alpha
    self%w = contact_line%trib
  end subroutine constant_setup

  !> corr(:, 1) = corr(:, 2) = alpha d ./ w (no Hessian-sized product).
  subroutine constant_apply(self, d, corr, count)
    class(constant_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    corr(:, 1) = self%alpha*d/self%w
    corr(:, 2) = corr(:, 1)
  end subroutine constant_apply

  ! ---- harmonic --------------------------------------------------------------------------

  subroutine harmonic_setup(self, solver, contact_line, bodies, flexibility, err)
    class(harmonic_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(2)
    type(dense_op_t), target, intent(in) :: flexibility(2)
    type(error_t), intent(out) :: err
    real(wp), allocatable :: s(:, :)
    integer :: m, info
    character(len=100) :: emsg
    info = 0
    m = contact_line%m
    if (m == 0) return
    if (bodies(1)%nrig + bodies(2)%nrig > 0) then
      call harmonic_floating(bodies, s, info)
    else
      call harmonic_matrix(bodies(1)%flex, bodies(2)%flex, s, info)
    end if
    if (info /= 0 .and. bodies(1)%nrig + bodies(2)%nrig > 0 .and. (bodies(1)%rank < m .or. bodies(2)%rank < m)) then
      call err%set(ERR_NUMERICAL, 'harmonic operator: a body held only by contact is a mortar master coarser than '// &
                   'the slave (singular F): make it the slave (&contact slave), or use steklov or monolithic')
    else if (info /= 0) then
      write (emsg, '(a,i0)') 'harmonic Robin operator: F_1 + F_2 is not positive definite, info = ', info
      call err%set(ERR_NUMERICAL, emsg)
    else
      call dense_op_init(self%s, s)
    end if
  end subroutine harmonic_setup

  subroutine harmonic_apply(self, d, corr, count)
    class(harmonic_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    call self%s%apply(d, corr(:, 1))
    corr(:, 2) = corr(:, 1)
    count = count + 1
  end subroutine harmonic_apply

  !> The linearised outer map is nilpotent at delta = 0.5: the outer iteration is as exact
  !! as its subproblems, so they are solved tightly, scaled by the contrast of the bodies,
  !! down to what rounding lets the projected gradient reach (about sqrt(m) eps: asking for
  !! less only spins MPRGP up to inner_max_it) (doc/method.md, "Method as implemented", why 'harmonic').
  real(wp) function harmonic_tolerance(self, solver, it, m, progress, lmax) result(rtol_in)
    class(harmonic_operator_t), intent(in) :: self
    type(solver_cfg_t), intent(in) :: solver
    integer, intent(in) :: it, m
    real(wp), intent(in) :: progress, lmax(2)
    rtol_in = max(sqrt(real(max(m, 1), wp))*epsilon(1.0_wp), &
                  solver%inner_factor*solver%tol*minval(lmax)/max(maxval(lmax), tiny(1.0_wp)))
  end function harmonic_tolerance

  !> POWER_ITS power iterations (the inner tolerance uses the ratio of the two bodies'
  !! estimates, which the row-sum bound would distort).
  real(wp) function power_estimate(self, flexibility, flex, nmv) result(lmax)
    class(harmonic_operator_t), intent(in) :: self
    type(dense_op_t), intent(inout) :: flexibility
    real(wp), intent(in) :: flex(:, :)
    integer, intent(out) :: nmv
    lmax = lambda_max_estimate(flexibility, POWER_ITS, nmv)
  end function power_estimate

  !> Pi_a = Z R Z' on ker F_a only (Z its basis, R = Z' F_o Z floored): S annihilates
  !! ker F_a, so only the kernel needs pinning, and the body stays exact on range F_a.
  !! Without a kernel basis, F_o (doc/method.md, "Non-matching and curved contact surfaces:
  !! dual mortar").
  subroutine kernel_proximal(self, bodies, a, p)
    class(harmonic_operator_t), intent(in) :: self
    type(body_condensed_t), intent(in) :: bodies(2)
    integer, intent(in) :: a
    real(wp), intent(out) :: p(:, :)
    real(wp), allocatable :: zf(:, :), zr(:, :), r(:, :)
    real(wp) :: floor
    integer :: i, k, m, o
    if (.not. allocated(bodies(a)%kern)) then
      call other_flexibility(self, bodies, a, p)
      return
    end if
    m = bodies(a)%m
    o = other_body(a)
    k = size(bodies(a)%kern, 2)
    allocate (zf(k, m), zr(m, k), r(k, k))
    ! R = Z' F_o Z (k x k), floored so that F_a + Pi_a is definite even if F_o is nearly
    ! singular on ker F_a
    call dgemm('T', 'N', k, m, m, 1.0_wp, bodies(a)%kern, m, bodies(o)%flex, m, 0.0_wp, zf, k)
    call dgemm('N', 'N', k, k, m, 1.0_wp, zf, k, bodies(a)%kern, m, 0.0_wp, r, k)
    r = 0.5_wp*(r + transpose(r))
    floor = 0.0_wp
    do i = 1, m
      floor = max(floor, 1.0e-10_wp*bodies(o)%flex(i, i))
    end do
    do i = 1, k
      r(i, i) = r(i, i) + floor
    end do
    call dgemm('N', 'N', m, k, k, 1.0_wp, bodies(a)%kern, m, r, k, 0.0_wp, zr, m)
    call dgemm('N', 'T', m, m, k, 1.0_wp, zr, m, bodies(a)%kern, m, 0.0_wp, p, m)
    p = 0.5_wp*(p + transpose(p))
  end subroutine kernel_proximal

  !> S = 2 F_1 (F_1 + F_2)^-1 F_2 = 2 (F_1^-1 + F_2^-1)^-1 (symmetric positive definite).
  subroutine harmonic_matrix(f1, f2, s, info)
    real(wp), intent(in) :: f1(:, :), f2(:, :)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: a(:, :), x(:, :)
    integer :: m
    m = size(f1, 1)
    allocate (a(m, m), x(m, m), s(m, m))
    a = f1 + f2
    x = f2
    call dposv('U', m, m, a, m, x, m, info)
    if (info /= 0) return
    call dgemm('N', 'N', m, m, m, 2.0_wp, f1, m, x, m, 0.0_wp, s, m)
    s = 0.5_wp*(s + transpose(s))
  end subroutine harmonic_matrix

  !> The harmonic operator with a floating body: S = 2 (Sigma_1 + Sigma_2)^-1, Sigma_a = F_a^-1
  !! for a supported body and the projected inverse Q_a (`projected_inverse`) for a floating
  !! one (doc/method.md, "Bodies held only by contact"). One floating body f, the other o
  !! supported: S = 2 (I + F_o Q_f)^-1 F_o (no inverse of F_o). Both floating:
  !! S = 2 (Q_1 + Q_2)^-1. info /= 0: a factorization failed.
  subroutine harmonic_floating(bodies, s, info)
    type(body_condensed_t), intent(in) :: bodies(2)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: q(:, :, :), a(:, :)
    integer, allocatable :: ipiv(:)
    integer :: m, f, o, i
    m = bodies(1)%m
    allocate (q(m, m, 2), s(m, m), a(m, m), ipiv(m))
    do f = 1, 2
      if (bodies(f)%nrig == 0) cycle
      call projected_inverse(bodies(f), q(:, :, f), info)
      if (info /= 0) return
    end do
    if (bodies(1)%nrig > 0 .and. bodies(2)%nrig > 0) then
      a = q(:, :, 1) + q(:, :, 2)
      a = 0.5_wp*(a + transpose(a))
      s = 0.0_wp
      do i = 1, m
        s(i, i) = 2.0_wp
      end do
      call dposv('U', m, m, a, m, s, m, info)
    else
      f = merge(1, 2, bodies(1)%nrig > 0)
      o = other_body(f)
      ! (I + F_o Q_f) X = F_o, S = 2 X
      a = matmul(bodies(o)%flex, q(:, :, f))
      do i = 1, m
        a(i, i) = a(i, i) + 1.0_wp
      end do
      s = 2.0_wp*bodies(o)%flex
      call dgesv(m, m, a, m, ipiv, s, m, info)
    end if
    s = 0.5_wp*(s + transpose(s))
  end subroutine harmonic_floating

  !> The projected inverse Q = F^-1 - F^-1 G' (G F^-1 G')^-1 G F^-1 of a floating body.
  subroutine projected_inverse(body, q, info)
    type(body_condensed_t), intent(in) :: body
    real(wp), intent(out) :: q(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: h(:, :), y(:, :), gg(:, :), t(:, :)
    integer :: m, r, i
    m = body%m
    r = body%nrig
    allocate (h(m, m), y(m, r), gg(r, r), t(r, m))
    h = body%flex
    q = 0.0_wp
    do i = 1, m
      q(i, i) = 1.0_wp
    end do
    call dposv('U', m, m, h, m, q, m, info)
    if (info /= 0) return
    ! y = F^-1 G', gg = G F^-1 G': q -= y gg^-1 y'
    y = matmul(q, transpose(body%rg))
    gg = matmul(body%rg, y)
    t = transpose(y)
    call dposv('U', r, m, gg, r, t, r, info)
    if (info /= 0) return
    q = q - matmul(y, t)
    q = 0.5_wp*(q + transpose(q))
  end subroutine projected_inverse

end module robin_operators
