!> The feasible set of a QP with friction in 3D: a box on some variables (the normal forces,
!! l >= 0) and discs on pairs of the others (a node's two tangential forces, |(x_a, x_b)| <= r,
!! Tresca's bound g D for r). METHOD-3D section 5: MPGP is MPRGP whose box is replaced by a
!! separable convex set whose pieces are easy to project on, reached through the same
!! `constraint_set_t` procedures.
!!
!! A disc's variables are the box's unbounded ones (lb = -huge, ub = +huge), so every
!! procedure below first runs the box's on all variables and then corrects each disc:
!!   on the circle     |x_k| >= (1 - CIRCLE_RTOL) r_k (a disc of radius 0 is a fixed point);
!!   free              strictly inside; both variables of a disc are free or not alike;
!!   projection        x_k scaled back onto the circle when |x_k| > r_k;
!!   chopped gradient  on the circle, with nu = x_k / |x_k| its outward normal,
!!                     beta_k = g_k - min(nu.g_k, 0) nu: the gradient's part along the circle
!!                     and its inward normal part (zero exactly at a KKT point g_k = -s nu,
!!                     s >= 0); 0 on a disc of radius 0;
!!   reduced free gradient  phit_k = (x_k - P(x_k - alpha g_k)) / alpha;
!!   steps             the root t >= 0 of |x_k + t d_k| = r_k (the form without cancellation
!!                     for either sign of x_k.d_k); the blocker of a step is a disc's first
!!                     variable, and `pin` puts that disc on its circle.
!! The set is not linear (its faces are curved): MPRGP's proportioning step along -beta
!! leaves a disc to second order, so it is projected and the gradient computed again
!! (module mprgp), and its active-set Newton method is module disc_newton's (a Newton step
!! along the circles), not qp_newton's. `binding` (a disc on its circle whose gradient does
!! not point into it) is disc_newton's working set; `leaving` and `settle` answer for a disc
!! too, so that the set is whole.
!!
!! Thread safety: no module variables.
module tangent_discs
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use constraint_set, only: constraint_set_t, box_set_t, box_set, set_projected_gradient_norm
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  implicit none (type, external)
  private

  public :: disc_set_t, disc_set, circle_point, friction_set

  real(wp), parameter :: big = huge(1.0_wp)
  !> A point within this relative distance of its circle is on it (a projected point lands
  !! on the circle only to rounding).
  real(wp), parameter :: CIRCLE_RTOL = 8.0_wp*epsilon(1.0_wp)

  !> A box on the variables outside the discs and a disc |(x_a, x_b)| <= r on each pair.
  type, extends(box_set_t) :: disc_set_t
    integer, allocatable :: disc(:)      !< (n) the disc of each variable (0: a box variable)
    integer, allocatable :: pair(:, :)   !< (2, nd) the two variables of each disc, the lower first
    real(wp), allocatable :: r(:)        !< (nd) the radii (>= 0)
  contains
    procedure :: validate => disc_validate
    procedure :: linear => disc_linear
    procedure :: boundary_curvature => disc_boundary_curvature
    procedure :: project => disc_project
    procedure :: free_mask => disc_free_mask
    procedure :: move => disc_move
    procedure :: free_gradient => disc_free_gradient
    procedure :: split_gradient => disc_split_gradient
    procedure :: projected_gradient_norm => disc_projected_gradient_norm
    procedure :: chopped_gradient => disc_chopped_gradient
    procedure :: projected_gradient => disc_projected_gradient
    procedure :: reduced_gradient => disc_reduced_gradient
    procedure :: projected_step => disc_projected_step
    procedure :: max_step => disc_max_step
    procedure :: pin => disc_pin
    procedure :: cut_step => disc_cut_step
    procedure :: step_bound => disc_step_bound
    procedure :: binding => disc_binding
    procedure :: leaving => disc_leaving
    procedure :: settle => disc_settle
  end type disc_set_t

contains

  !> The box lb <= x <= ub (without ub: x >= lb) on the variables outside the discs, and
  !! |(x(pair(1,k)), x(pair(2,k)))| <= r(k); a disc variable's lb and ub are ignored. A pair
  !! outside 1..n or a variable in two pairs is left for `validate` to report.
  function disc_set(lb, pair, r, ub) result(set)
    real(wp), intent(in) :: lb(:)             !< lower bounds (-huge(1.0_wp): none)
    integer, intent(in) :: pair(:, :)         !< (2, nd) the variables of each disc
    real(wp), intent(in) :: r(:)              !< (nd) radii
    real(wp), intent(in), optional :: ub(:)   !< upper bounds (+huge(1.0_wp): none)
    type(disc_set_t) :: set
    integer :: k, j, i
    allocate (set%lb, source=lb)
    if (present(ub)) then
      allocate (set%ub, source=ub)
    else
      allocate (set%ub(size(lb)), source=big)
    end if
    allocate (set%disc(size(lb)), source=0)
    allocate (set%pair(2, size(pair, 2)), set%r(size(r)))
    set%r = r
    do k = 1, size(pair, 2)
      set%pair(:, k) = [minval(pair(:, k)), maxval(pair(:, k))]
      do j = 1, 2
        i = pair(j, k)
        if (i < 1 .or. i > size(lb)) cycle
        ! a variable already in a disc keeps the first (validate reports it)
        if (set%disc(i) == 0) set%disc(i) = k
        set%lb(i) = -big
        set%ub(i) = big
      end do
    end do
  end function disc_set

  !> The feasible set of contact forces: the box lb <= x <= ub, or, with discs (pair(:, k) the
  !! two tangential forces of a node in space), the box on the other variables and the disc of
  !! radius ub(pair(1, k)) on each pair.
  function friction_set(lb, ub, pair) result(set)
    real(wp), intent(in) :: lb(:), ub(:)      !< the bounds (a disc's variables: -r and r)
    integer, intent(in) :: pair(:, :)         !< (2, nd) the discs' variables; nd = 0: a box
    class(constraint_set_t), allocatable :: set
    if (size(pair, 2) > 0) then
      allocate (set, source=disc_set(lb, pair, ub(pair(1, :)), ub))
    else
      allocate (set, source=box_set(lb, ub))
    end if
  end function friction_set

  !> Not linear: the discs' boundaries are curved.
  logical function disc_linear(self) result(yes)
    class(disc_set_t), intent(in) :: self
    yes = .false.
  end function disc_linear

  !> sum over the discs on their circles of (s_k / r_k) |d_k - (nu.d_k) nu|^2, s_k = max(-nu.g_k, 0)
  !! the force that presses the disc's point outwards: sliding by d_k along a circle of radius
  !! r_k and projecting back moves the point inwards by |d_k|^2 / (2 r_k) against that force
  !! (the Lagrangian's Hessian s_k / r_k on the circle's tangent).
  real(wp) function disc_boundary_curvature(self, x, g, d) result(c)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:), d(:)   !< iterate, gradient, direction
    real(wp) :: s, na, nb, press, dn
    integer :: k
    c = 0.0_wp
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (self%r(k) <= 0.0_wp .or. .not. on_circle(x(a), x(b), self%r(k))) cycle
        s = hypot(x(a), x(b))
        na = x(a)/s
        nb = x(b)/s
        press = max(-(na*g(a) + nb*g(b)), 0.0_wp)
        dn = na*d(a) + nb*d(b)
        c = c + (press/self%r(k))*((d(a) - dn*na)**2 + (d(b) - dn*nb)**2)
      end associate
    end do
  end function disc_boundary_curvature

  !> The box's checks, then: one radius per pair, radii finite and >= 0, pairs of two
  !! different variables in 1..n, no variable in two pairs.
  subroutine disc_validate(self, n, err)
    class(disc_set_t), intent(in) :: self
    integer, intent(in) :: n                !< unknowns
    type(error_t), intent(out) :: err       !< ERR_INPUT or ERR_NUMERICAL and why
    character(len=120) :: buf
    integer :: k, j, i
    integer, allocatable :: seen(:)
    call self%box_set_t%validate(n, err)
    if (err%failed()) return
    if (size(self%r) /= size(self%pair, 2) .or. size(self%disc) /= n) then
      write (buf, '(a,i0,a,i0)') 'size mismatch: ', size(self%pair, 2), ' pairs, radii ', size(self%r)
      call err%set(ERR_INPUT, trim(buf))
      return
    end if
    allocate (seen(n), source=0)
    do k = 1, size(self%r)
      ! (two tests: an ordered comparison with a NaN would raise the invalid flag)
      if (.not. ieee_is_finite(self%r(k))) then
        write (buf, '(a,i0,a)') 'r(', k, ') is not a finite radius >= 0'
        call err%set(ERR_NUMERICAL, trim(buf))
        return
      end if
      if (self%r(k) < 0.0_wp) then
        write (buf, '(a,i0,a)') 'r(', k, ') is not a finite radius >= 0'
        call err%set(ERR_INPUT, trim(buf))
        return
      end if
      do j = 1, 2
        i = self%pair(j, k)
        if (i < 1 .or. i > n) then
          write (buf, '(a,i0,a,i0,a,i0)') 'pair ', k, ' names variable ', i, ' outside 1..', n
          call err%set(ERR_INPUT, trim(buf))
          return
        end if
        if (seen(i) /= 0) then
          write (buf, '(a,i0,a,i0,a,i0)') 'variable ', i, ' is in pair ', seen(i), ' and in pair ', k
          call err%set(ERR_INPUT, trim(buf))
          return
        end if
        seen(i) = k
      end do
    end do
  end subroutine disc_validate

  ! ---- one disc ------------------------------------------------------------------

  !> |x_k| on or beyond the circle of radius r (to CIRCLE_RTOL).
  pure logical function on_circle(xa, xb, r) result(on)
    real(wp), intent(in) :: xa, xb, r
    on = hypot(xa, xb) >= r*(1.0_wp - CIRCLE_RTOL)
  end function on_circle

  !> The unit outward normal (na, nb) of a point (xa, xb) of a circle and its distance s from
  !! the centre ((1, 0) at the centre).
  pure subroutine circle_point(xa, xb, na, nb, s)
    real(wp), intent(in) :: xa, xb
    real(wp), intent(out) :: na, nb, s
    s = hypot(xa, xb)
    if (s > 0.0_wp) then
      na = xa/s
      nb = xb/s
    else
      na = 1.0_wp
      nb = 0.0_wp
    end if
  end subroutine circle_point

  !> (xa, xb) scaled onto the disc of radius r when outside it.
  pure subroutine project_point(xa, xb, r)
    real(wp), intent(inout) :: xa, xb
    real(wp), intent(in) :: r
    real(wp) :: s
    s = hypot(xa, xb)
    if (s <= r) return
    if (r > 0.0_wp) then
      xa = xa*(r/s)
      xb = xb*(r/s)
    else
      xa = 0.0_wp
      xb = 0.0_wp
    end if
  end subroutine project_point

  !> The chopped gradient of a point on its circle: g - min(nu.g, 0) nu (0 at radius 0).
  pure subroutine chopped_point(xa, xb, r, ga, gb, ba, bb)
    real(wp), intent(in) :: xa, xb, r, ga, gb
    real(wp), intent(out) :: ba, bb
    real(wp) :: s, na, nb, gn
    s = hypot(xa, xb)
    if (r <= 0.0_wp .or. s <= 0.0_wp) then
      ba = 0.0_wp
      bb = 0.0_wp
      return
    end if
    na = xa/s
    nb = xb/s
    gn = min(na*ga + nb*gb, 0.0_wp)
    ba = ga - gn*na
    bb = gb - gn*nb
  end subroutine chopped_point

  !> The step t >= 0 at which x + t d reaches the circle of radius r from a point inside it
  !! (a point beyond it counts as on it); huge when d = 0.
  pure real(wp) function root(xa, xb, da, db, r) result(t)
    real(wp), intent(in) :: xa, xb, da, db, r
    real(wp) :: a, bq, c, disc
    ! no step reaches a circle of radius huge (no bound: Coulomb's first solve)
    if (r >= big) then
      t = big
      return
    end if
    a = da*da + db*db
    if (a <= 0.0_wp) then
      t = big
      return
    end if
    bq = xa*da + xb*db
    c = min(xa*xa + xb*xb - r*r, 0.0_wp)
    disc = sqrt(bq*bq - a*c)
    if (bq > 0.0_wp) then
      t = -c/(bq + disc)
    else
      t = (disc - bq)/a
    end if
  end function root

  ! ---- the set's procedures: the box's, then each disc -----------------------------

  !> x = P(x).
  subroutine disc_project(self, x)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)   !< in: any point; out: its projection
    integer :: k
    call self%box_set_t%project(x)
    do k = 1, size(self%r)
      call project_point(x(self%pair(1, k)), x(self%pair(2, k)), self%r(k))
    end do
  end subroutine disc_project

  !> free(i): a box variable strictly between its bounds, a disc's strictly inside it.
  subroutine disc_free_mask(self, x, free)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:)      !< iterate
    logical, intent(out) :: free(:)   !< the free set
    integer :: k
    call self%box_set_t%free_mask(x, free)
    do k = 1, size(self%r)
      free(self%pair(:, k)) = .not. on_circle(x(self%pair(1, k)), x(self%pair(2, k)), self%r(k))
    end do
  end subroutine disc_free_mask

  !> x = P(x + t d) and the free set there.
  subroutine disc_move(self, x, d, t, free)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:), t      !< direction, step
    logical, intent(out) :: free(:)      !< the free set at the new x
    integer :: k
    call self%box_set_t%move(x, d, t, free)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        call project_point(x(a), x(b), self%r(k))
        free([a, b]) = .not. on_circle(x(a), x(b), self%r(k))
      end associate
    end do
  end subroutine disc_move

  !> phi: g on the free set, 0 elsewhere.
  subroutine disc_free_gradient(self, x, g, v)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< phi
    integer :: k
    call self%box_set_t%free_gradient(x, g, v)
    do k = 1, size(self%r)
      if (on_circle(x(self%pair(1, k)), x(self%pair(2, k)), self%r(k))) v(self%pair(:, k)) = 0.0_wp
    end do
  end subroutine disc_free_gradient

  !> |phi|^2, phit'phi and |beta|^2 from the three gradients, summed in index order.
  subroutine disc_split_gradient(self, x, g, alpha, phiphi, phitphi, betabeta)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length of phit (<= 0: phit = phi)
    real(wp), intent(out) :: phiphi, phitphi, betabeta   !< the three sums
    real(wp), allocatable :: phi(:), phit(:), beta(:)
    integer :: i
    allocate (phi(size(x)), phit(size(x)), beta(size(x)))
    call self%free_gradient(x, g, phi)
    call self%reduced_gradient(x, g, alpha, phit)
    call self%chopped_gradient(x, g, beta)
    phiphi = 0.0_wp
    phitphi = 0.0_wp
    betabeta = 0.0_wp
    do i = 1, size(x)
      phiphi = phiphi + phi(i)*phi(i)
      phitphi = phitphi + phit(i)*phi(i)
      betabeta = betabeta + beta(i)*beta(i)
    end do
  end subroutine disc_split_gradient

  !> |gP|, summed in index order (the generic one: the box's one-pass sum knows no discs).
  real(wp) function disc_projected_gradient_norm(self, x, g) result(r)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:)    !< iterate
    real(wp), intent(in) :: g(:)    !< gradient
    r = set_projected_gradient_norm(self, x, g)
  end function disc_projected_gradient_norm

  !> beta: the box's on its variables, g - min(nu.g, 0) nu on a disc's circle, 0 inside.
  subroutine disc_chopped_gradient(self, x, g, v)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< beta
    integer :: k
    call self%box_set_t%chopped_gradient(x, g, v)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (on_circle(x(a), x(b), self%r(k))) then
          call chopped_point(x(a), x(b), self%r(k), g(a), g(b), v(a), v(b))
        else
          v([a, b]) = 0.0_wp
        end if
      end associate
    end do
  end subroutine disc_chopped_gradient

  !> gP = phi + beta.
  subroutine disc_projected_gradient(self, x, g, v)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< gP
    integer :: k
    call self%box_set_t%projected_gradient(x, g, v)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (on_circle(x(a), x(b), self%r(k))) call chopped_point(x(a), x(b), self%r(k), g(a), g(b), v(a), v(b))
      end associate
    end do
  end subroutine disc_projected_gradient

  !> phit: on a free disc (x - P(x - alpha g)) / alpha (g itself while alpha <= 0), 0 on
  !! its circle.
  subroutine disc_reduced_gradient(self, x, g, alpha, v)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length (<= 0: not known)
    real(wp), intent(out) :: v(:)        !< phit
    real(wp) :: ya, yb
    integer :: k
    call self%box_set_t%reduced_gradient(x, g, alpha, v)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (on_circle(x(a), x(b), self%r(k))) then
          v([a, b]) = 0.0_wp
        else if (alpha > 0.0_wp) then
          ya = x(a) - alpha*g(a)
          yb = x(b) - alpha*g(b)
          call project_point(ya, yb, self%r(k))
          v(a) = (x(a) - ya)/alpha
          v(b) = (x(b) - yb)/alpha
        end if
      end associate
    end do
  end subroutine disc_reduced_gradient

  !> d = P(x - alpha phi) - x.
  subroutine disc_projected_step(self, x, g, alpha, v)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length
    real(wp), intent(out) :: v(:)        !< d
    real(wp) :: ya, yb
    integer :: k
    call self%box_set_t%projected_step(x, g, alpha, v)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (on_circle(x(a), x(b), self%r(k))) then
          v([a, b]) = 0.0_wp
        else
          ya = x(a) - alpha*g(a)
          yb = x(b) - alpha*g(b)
          call project_point(ya, yb, self%r(k))
          v(a) = ya - x(a)
          v(b) = yb - x(b)
        end if
      end associate
    end do
  end subroutine disc_projected_step

  !> The box's cut, then each disc's root when it is shorter (the blocker: its first variable).
  subroutine disc_max_step(self, x, d, tmax, t, blocker)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(in) :: tmax         !< the step wanted
    real(wp), intent(out) :: t           !< the longest feasible step up to tmax
    integer, intent(out) :: blocker      !< the variable that cut it (0: none)
    real(wp) :: tk
    integer :: k
    call self%box_set_t%max_step(x, d, tmax, t, blocker)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        tk = root(x(a), x(b), d(a), d(b), self%r(k))
        if (tk < t) then
          t = tk
          blocker = a
        end if
      end associate
    end do
  end subroutine disc_max_step

  !> A blocking disc onto its circle (scaled); a box variable onto its bound.
  subroutine disc_pin(self, x, d, blocker)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:)         !< the direction of the step that was cut
    integer, intent(in) :: blocker       !< from max_step (0: nothing to do)
    real(wp) :: s
    integer :: k
    if (blocker <= 0) return
    k = self%disc(blocker)
    if (k == 0) then
      call self%box_set_t%pin(x, d, blocker)
      return
    end if
    associate (a => self%pair(1, k), b => self%pair(2, k))
      s = hypot(x(a), x(b))
      if (s > 0.0_wp .and. self%r(k) > 0.0_wp) then
        x(a) = x(a)*(self%r(k)/s)
        x(b) = x(b)*(self%r(k)/s)
      else if (self%r(k) <= 0.0_wp) then
        x(a) = 0.0_wp
        x(b) = 0.0_wp
      end if
    end associate
  end subroutine disc_pin

  !> The box's cut, then t cut to each disc's root where x + t d leaves it (with whole: the
  !! step is refused instead, t unchanged). True when a cut was needed.
  logical function disc_cut_step(self, x, d, t, whole) result(cut)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(inout) :: t         !< in: the step wanted; out: the feasible step
    logical, intent(in) :: whole         !< stop at the first cut, t unchanged
    integer :: k
    cut = self%box_set_t%cut_step(x, d, t, whole)
    if (cut .and. whole) return
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (hypot(x(a) + t*d(a), x(b) + t*d(b)) > self%r(k)) then
          cut = .true.
          if (whole) return
          t = max(0.0_wp, min(t, root(x(a), x(b), d(a), d(b), self%r(k))))
        end if
      end associate
    end do
  end function disc_cut_step

  !> min(tmax, the box's ratios, the discs' roots).
  real(wp) function disc_step_bound(self, x, d, tmax) result(t)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(in) :: tmax         !< the step wanted
    integer :: k
    t = self%box_set_t%step_bound(x, d, tmax)
    do k = 1, size(self%r)
      t = min(t, root(x(self%pair(1, k)), x(self%pair(2, k)), d(self%pair(1, k)), d(self%pair(2, k)), self%r(k)))
    end do
  end function disc_step_bound

  !> held: the box's; a disc on its circle whose gradient does not point into it (nu.g <= 0),
  !! or of radius 0.
  subroutine disc_binding(self, x, g, mask)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    logical, intent(out) :: mask(:)      !< held
    integer :: k
    call self%box_set_t%binding(x, g, mask)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        mask([a, b]) = on_circle(x(a), x(b), self%r(k)) .and. (self%r(k) <= 0.0_wp .or. x(a)*g(a) + x(b)*g(b) <= 0.0_wp)
      end associate
    end do
  end subroutine disc_binding

  !> out: the box's; a disc on its circle that d leaves (nu.d > 0).
  subroutine disc_leaving(self, x, g, mask)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, direction d
    logical, intent(out) :: mask(:)      !< out
    integer :: k
    call self%box_set_t%leaving(x, g, mask)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        mask([a, b]) = on_circle(x(a), x(b), self%r(k)) .and. x(a)*g(a) + x(b)*g(b) > 0.0_wp
      end associate
    end do
  end subroutine disc_leaving

  !> x_j += t d_j for j in idx (the box's landing on its bounds); a disc that ends on or
  !! beyond its circle is put on it and held.
  subroutine disc_settle(self, x, d, t, idx, held)
    class(disc_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:), t      !< direction, step
    integer, intent(in) :: idx(:)        !< the variables that move
    logical, intent(inout) :: held(:)    !< set where a variable lands on the boundary
    integer :: k
    call self%box_set_t%settle(x, d, t, idx, held)
    do k = 1, size(self%r)
      associate (a => self%pair(1, k), b => self%pair(2, k))
        if (on_circle(x(a), x(b), self%r(k))) then
          call project_point(x(a), x(b), self%r(k))
          held([a, b]) = .true.
        end if
      end associate
    end do
  end subroutine disc_settle

end module tangent_discs
