!> The feasible set of a QP solver as one object: the solvers (mprgp, qp_newton) reach their
!! constraints only through a `class(constraint_set_t)`, so a new kind of constraint is one
!! more extension of the type, not a branch in the solvers (the pattern of PERMON's QPC:
!! QPCProject, QPCGrads, QPCFeas).
!!
!! Terms (g = A x - b the gradient of 1/2 x'Ax - b'x at a feasible x):
!!   free set F        the variables not on the boundary of the set
!!   free gradient     phi = g on F, 0 elsewhere
!!   chopped gradient  beta: on the boundary, the part of g that would move x into the set
!!                     (0 on F and where the set leaves no freedom)
!!   projected gradient  gP = phi + beta, zero exactly at the minimiser
!!   reduced free gradient  phit: phi cut so that x - alpha phit stays in the set
!!
!! `box_set_t` is the set lb <= x <= ub (a lower bound -huge(1.0_wp) or an upper bound
!! +huge(1.0_wp) means "no bound"; without upper bounds ub = +huge, and then no upper-bound
!! branch is ever taken, so a lower-bound problem runs the same floating-point operations as
!! before the box existed).
!!
!! Where a method below computes one quantity in two ways (`max_step`, `cut_step` and
!! `step_bound` are each the feasible step length along a direction), the box keeps the
!! rounding of the solver step that uses each one (MPRGP's conjugate gradient and
!! proportioning steps, its line search, the Newton step); a new set may compute all three
!! the same way.
!!
!! A separable per-node disc |(x_a, x_b)| <= r (3D friction) is the extension `disc_set_t`
!! of module tangent_discs (a box on the other variables); its faces are curved, so it is not
!! `linear`.
module constraint_set
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  implicit none (type, external)
  private

  public :: constraint_set_t, box_set_t, box_set, chopped, set_projected_gradient_norm

  real(wp), parameter :: big = huge(1.0_wp)

  !> A closed convex feasible set of R^n, with what the QP solvers need of it.
  type, abstract :: constraint_set_t
  contains
    !> Check the set's data for n unknowns: ERR_INPUT (wrong sizes, an empty set) or
    !! ERR_NUMERICAL (a non-finite datum) and why.
    procedure(validate_i), deferred :: validate
    !> x = P(x), the Euclidean projection onto the set.
    procedure(project_i), deferred :: project
    !> free(i): x_i is not on the boundary of the set.
    procedure(free_mask_i), deferred :: free_mask
    !> x = P(x + t d), and the free set there.
    procedure(move_i), deferred :: move
    !> phi, the free gradient (g on the free set, 0 elsewhere).
    procedure(grad_i), deferred :: free_gradient
    !> |phi|^2, phit'phi and |beta|^2 in one pass (MPRGP's split of the gradient).
    procedure(split_i), deferred :: split_gradient
    !> beta, the chopped gradient (0 on the free set).
    procedure(grad_i), deferred :: chopped_gradient
    !> gP = phi + beta, the projected gradient.
    procedure(grad_i), deferred :: projected_gradient
    !> phit, the reduced free gradient for a step length alpha (phi itself when alpha <= 0).
    procedure(reduced_i), deferred :: reduced_gradient
    !> d = P(x - alpha phi) - x, the projected step along the free gradient.
    procedure(reduced_i), deferred :: projected_step
    !> The longest step t <= tmax with x + t d in the set, and the variable that blocks it.
    procedure(max_step_i), deferred :: max_step
    !> Put the variable that blocked a step along d exactly on the boundary.
    procedure(pin_i), deferred :: pin
    !> The step t along d cut where x + t d leaves the set (a line search's cut).
    procedure(cut_step_i), deferred :: cut_step
    !> The longest step up to tmax with x + t d in the set, as the least of the ratios.
    procedure(step_bound_i), deferred :: step_bound
    !> held(i): x_i is on the boundary and g_i does not point into the set (or x_i is fixed).
    procedure(binding_i), deferred :: binding
    !> out(i): x_i is on the boundary and d_i points out of the set.
    procedure(binding_i), deferred :: leaving
    !> x(idx) += t d(idx); those landing within rounding of the boundary go onto it and are held.
    procedure(settle_i), deferred :: settle
    !> |gP|.
    procedure :: projected_gradient_norm => set_projected_gradient_norm
    !> True when the set's faces are flat (a box): a step along a face direction stays on
    !! the face, which MPRGP's proportioning step and qp_newton's active-set method rely on.
    procedure :: linear => set_linear
    !> d' C d, the second-order change of the cost along the boundary that the curvature of
    !! its faces adds when x + t d is projected back (0 on flat faces).
    procedure :: boundary_curvature => set_boundary_curvature
  end type constraint_set_t

  abstract interface
    subroutine validate_i(self, n, err)
      import :: constraint_set_t, error_t
      class(constraint_set_t), intent(in) :: self
      integer, intent(in) :: n
      type(error_t), intent(out) :: err
    end subroutine validate_i
    subroutine project_i(self, x)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(inout) :: x(:)
    end subroutine project_i
    subroutine free_mask_i(self, x, free)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:)
      logical, intent(out) :: free(:)
    end subroutine free_mask_i
    subroutine move_i(self, x, d, t, free)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(inout) :: x(:)
      real(wp), intent(in) :: d(:), t
      logical, intent(out) :: free(:)
    end subroutine move_i
    subroutine split_i(self, x, g, alpha, phiphi, phitphi, betabeta)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), g(:), alpha
      real(wp), intent(out) :: phiphi, phitphi, betabeta
    end subroutine split_i
    subroutine grad_i(self, x, g, v)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), g(:)
      real(wp), intent(out) :: v(:)
    end subroutine grad_i
    subroutine reduced_i(self, x, g, alpha, v)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), g(:), alpha
      real(wp), intent(out) :: v(:)
    end subroutine reduced_i
    subroutine max_step_i(self, x, d, tmax, t, blocker)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), d(:), tmax
      real(wp), intent(out) :: t
      integer, intent(out) :: blocker
    end subroutine max_step_i
    subroutine pin_i(self, x, d, blocker)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(inout) :: x(:)
      real(wp), intent(in) :: d(:)
      integer, intent(in) :: blocker
    end subroutine pin_i
    logical function cut_step_i(self, x, d, t, whole) result(cut)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), d(:)
      real(wp), intent(inout) :: t
      logical, intent(in) :: whole
    end function cut_step_i
    real(wp) function step_bound_i(self, x, d, tmax) result(t)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), d(:), tmax
    end function step_bound_i
    subroutine binding_i(self, x, g, mask)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(in) :: x(:), g(:)
      logical, intent(out) :: mask(:)
    end subroutine binding_i
    subroutine settle_i(self, x, d, t, idx, held)
      import :: constraint_set_t, wp
      class(constraint_set_t), intent(in) :: self
      real(wp), intent(inout) :: x(:)
      real(wp), intent(in) :: d(:), t
      integer, intent(in) :: idx(:)
      logical, intent(inout) :: held(:)
    end subroutine settle_i
  end interface

  !> The box lb <= x <= ub (-huge / +huge: no bound on that side; lb = ub: a fixed variable).
  type, extends(constraint_set_t) :: box_set_t
    real(wp), allocatable :: lb(:)   !< lower bounds
    real(wp), allocatable :: ub(:)   !< upper bounds (+huge: none)
  contains
    procedure :: validate => box_validate
    procedure :: project => box_project
    procedure :: free_mask => box_free_mask
    procedure :: move => box_move
    procedure :: free_gradient => box_free_gradient
    procedure :: split_gradient => box_split_gradient
    procedure :: projected_gradient_norm => box_projected_gradient_norm
    procedure :: chopped_gradient => box_chopped_gradient
    procedure :: projected_gradient => box_projected_gradient
    procedure :: reduced_gradient => box_reduced_gradient
    procedure :: projected_step => box_projected_step
    procedure :: max_step => box_max_step
    procedure :: pin => box_pin
    procedure :: cut_step => box_cut_step
    procedure :: step_bound => box_step_bound
    procedure :: binding => box_binding
    procedure :: leaving => box_leaving
    procedure :: settle => box_settle
  end type box_set_t

contains

  !> The box lb <= x <= ub; without ub, x >= lb (ub = +huge).
  function box_set(lb, ub) result(box)
    real(wp), intent(in) :: lb(:)             !< lower bounds (-huge(1.0_wp): none)
    real(wp), intent(in), optional :: ub(:)   !< upper bounds (+huge(1.0_wp): none)
    type(box_set_t) :: box
    allocate (box%lb, source=lb)
    if (present(ub)) then
      allocate (box%ub, source=ub)
    else
      allocate (box%ub(size(lb)), source=big)
    end if
  end function box_set

  !> True: the faces of a box are flat (a set with curved faces overrides it).
  logical function set_linear(self) result(yes)
    class(constraint_set_t), intent(in) :: self
    yes = .true.
  end function set_linear

  !> 0: flat faces add no curvature.
  real(wp) function set_boundary_curvature(self, x, g, d) result(c)
    class(constraint_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:), d(:)   !< iterate, gradient, direction
    c = 0.0_wp
  end function set_boundary_curvature

  !> |gP| = sqrt(sum gP_i^2), summed in index order.
  real(wp) function set_projected_gradient_norm(self, x, g) result(r)
    class(constraint_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:)    !< iterate
    real(wp), intent(in) :: g(:)    !< gradient
    real(wp), allocatable :: gp(:)
    integer :: j
    allocate (gp(size(x)))
    call self%projected_gradient(x, g, gp)
    r = 0.0_wp
    do j = 1, size(x)
      r = r + gp(j)**2
    end do
    r = sqrt(r)
  end function set_projected_gradient_norm

  !> The projected gradient of one variable of a box: min(g, 0) at its lower bound,
  !! max(g, 0) at its upper bound, 0 when it is fixed (lb = ub); g itself when it is free.
  elemental real(wp) function chopped(g, x, lb, ub) result(beta)
    real(wp), intent(in) :: g, x, lb, ub  !< gradient, iterate, bounds
    if (x > lb .and. x < ub) then
      beta = g
    else if (x < ub) then
      beta = min(g, 0.0_wp)
    else if (x > lb) then
      beta = max(g, 0.0_wp)
    else
      beta = 0.0_wp
    end if
  end function chopped

  !> Sizes n, finite bounds (-huge / +huge for none), lb <= ub.
  subroutine box_validate(self, n, err)
    class(box_set_t), intent(in) :: self
    integer, intent(in) :: n                !< unknowns
    type(error_t), intent(out) :: err       !< ERR_INPUT or ERR_NUMERICAL and why
    character(len=80) :: buf
    integer :: i
    if (size(self%lb) /= n .or. size(self%ub) /= n) then
      write (buf, '(a,i0,a,i0,a,i0)') 'size mismatch: A%n = ', n, ', size(lb) = ', size(self%lb), &
        ', size(ub) = ', size(self%ub)
      call err%set(ERR_INPUT, trim(buf))
      return
    end if
    do i = 1, n
      if (.not. ieee_is_finite(self%lb(i))) then
        write (buf, '(i0)') i
        call err%set(ERR_NUMERICAL, 'lb('//trim(buf)//') is not finite (use -huge(1.0_wp) for no bound)')
        return
      end if
      if (.not. ieee_is_finite(self%ub(i))) then
        write (buf, '(i0)') i
        call err%set(ERR_NUMERICAL, 'ub('//trim(buf)//') is not finite (use huge(1.0_wp) for no bound)')
        return
      end if
      if (self%ub(i) < self%lb(i)) then
        write (buf, '(i0)') i
        call err%set(ERR_INPUT, 'ub('//trim(buf)//') < lb('//trim(buf)//'): the box is empty')
        return
      end if
    end do
  end subroutine box_validate

  !> x = min(max(x, lb), ub).
  subroutine box_project(self, x)
    class(box_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)   !< in: any point; out: its projection
    integer :: i
    do i = 1, size(x)
      x(i) = min(max(x(i), self%lb(i)), self%ub(i))
    end do
  end subroutine box_project

  !> free(i) = lb_i < x_i < ub_i.
  subroutine box_free_mask(self, x, free)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:)      !< iterate
    logical, intent(out) :: free(:)   !< the free set
    integer :: i
    do i = 1, size(x)
      free(i) = x(i) > self%lb(i) .and. x(i) < self%ub(i)
    end do
  end subroutine box_free_mask

  !> x = min(max(x + t d, lb), ub), and free(i) = lb_i < x_i < ub_i there.
  subroutine box_move(self, x, d, t, free)
    class(box_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:), t      !< direction, step
    logical, intent(out) :: free(:)      !< the free set at the new x
    integer :: i
    do i = 1, size(x)
      x(i) = min(max(x(i) + t * d(i), self%lb(i)), self%ub(i))
      free(i) = x(i) > self%lb(i) .and. x(i) < self%ub(i)
    end do
  end subroutine box_move

  !> phi_i = g_i when lb_i < x_i < ub_i, else 0.
  subroutine box_free_gradient(self, x, g, v)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< phi
    integer :: i
    do i = 1, size(x)
      if (x(i) > self%lb(i) .and. x(i) < self%ub(i)) then
        v(i) = g(i)
      else
        v(i) = 0.0_wp
      end if
    end do
  end subroutine box_free_gradient

  !> One pass: |phi|^2 and phit'phi over the free variables, |beta|^2 over the others,
  !! each summed in index order.
  subroutine box_split_gradient(self, x, g, alpha, phiphi, phitphi, betabeta)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length of phit (<= 0: not known, phit = phi)
    real(wp), intent(out) :: phiphi, phitphi, betabeta   !< the three sums
    real(wp) :: phi, phit, beta, slack
    integer :: i
    phiphi = 0.0_wp
    phitphi = 0.0_wp
    betabeta = 0.0_wp
    do i = 1, size(x)
      if (x(i) > self%lb(i) .and. x(i) < self%ub(i)) then
        phi = g(i)
        phiphi = phiphi + phi * phi
        phit = phi
        if (alpha > 0.0_wp) then
          if (self%lb(i) > -big) then
            slack = x(i) - self%lb(i)
            if (slack < alpha * phi) phit = slack / alpha
          end if
          if (self%ub(i) < big) then
            slack = self%ub(i) - x(i)
            if (slack < -alpha * phi) phit = -slack / alpha
          end if
        end if
        phitphi = phitphi + phit * phi
      else
        beta = chopped(g(i), x(i), self%lb(i), self%ub(i))
        betabeta = betabeta + beta * beta
      end if
    end do
  end subroutine box_split_gradient

  !> |gP| in one pass (no work array).
  real(wp) function box_projected_gradient_norm(self, x, g) result(r)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:)    !< iterate
    real(wp), intent(in) :: g(:)    !< gradient
    integer :: j
    r = 0.0_wp
    do j = 1, size(x)
      r = r + chopped(g(j), x(j), self%lb(j), self%ub(j))**2
    end do
    r = sqrt(r)
  end function box_projected_gradient_norm

  !> beta_i = min(g_i, 0) at lb, max(g_i, 0) at ub, 0 when free or fixed.
  subroutine box_chopped_gradient(self, x, g, v)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< beta
    integer :: i
    do i = 1, size(x)
      if (x(i) > self%lb(i) .and. x(i) < self%ub(i)) then
        v(i) = 0.0_wp
      else
        v(i) = chopped(g(i), x(i), self%lb(i), self%ub(i))
      end if
    end do
  end subroutine box_chopped_gradient

  !> gP_i = g_i when free, else beta_i.
  subroutine box_projected_gradient(self, x, g, v)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(out) :: v(:)        !< gP
    integer :: i
    do i = 1, size(x)
      v(i) = chopped(g(i), x(i), self%lb(i), self%ub(i))
    end do
  end subroutine box_projected_gradient

  !> phit_i of a free variable: g_i cut to (x - lb)/alpha when g_i > 0 and to (x - ub)/alpha
  !! when g_i < 0, so that x - alpha phit stays in the box (g_i itself while alpha <= 0);
  !! 0 off the free set.
  subroutine box_reduced_gradient(self, x, g, alpha, v)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length (<= 0: not known)
    real(wp), intent(out) :: v(:)        !< phit
    real(wp) :: slack
    integer :: i
    do i = 1, size(x)
      if (.not. (x(i) > self%lb(i) .and. x(i) < self%ub(i))) then
        v(i) = 0.0_wp
        cycle
      end if
      v(i) = g(i)
      if (alpha <= 0.0_wp) cycle
      if (self%lb(i) > -big) then
        slack = x(i) - self%lb(i)
        if (slack < alpha * g(i)) v(i) = slack / alpha
      end if
      if (self%ub(i) < big) then
        slack = self%ub(i) - x(i)
        if (slack < -alpha * g(i)) v(i) = -slack / alpha
      end if
    end do
  end subroutine box_reduced_gradient

  !> d_i = max(lb_i - x_i, -alpha g_i) capped at ub_i - x_i on the free set, 0 elsewhere:
  !! x + d = P(x - alpha phi).
  subroutine box_projected_step(self, x, g, alpha, v)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    real(wp), intent(in) :: alpha        !< step length
    real(wp), intent(out) :: v(:)        !< d
    integer :: i
    do i = 1, size(x)
      if (x(i) > self%lb(i) .and. x(i) < self%ub(i)) then
        v(i) = max(self%lb(i) - x(i), -alpha * g(i))
        if (self%ub(i) < big) v(i) = min(v(i), self%ub(i) - x(i))
      else
        v(i) = 0.0_wp
      end if
    end do
  end subroutine box_projected_step

  !> Successive cuts: t = tmax, then for each variable moving towards a finite bound with
  !! slack < t |d_i|, t = slack / |d_i| and it becomes the blocker (no division can
  !! overflow); blocker = 0 when x + tmax d stays in the box. t may be negative when x is
  !! outside the box (the caller clamps).
  subroutine box_max_step(self, x, d, tmax, t, blocker)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(in) :: tmax         !< the step wanted
    real(wp), intent(out) :: t           !< the longest feasible step up to tmax
    integer, intent(out) :: blocker      !< the variable that cut it (0: none)
    real(wp) :: slack
    integer :: i
    t = tmax
    blocker = 0
    do i = 1, size(x)
      if (d(i) < 0.0_wp .and. self%lb(i) > -big) then
        slack = x(i) - self%lb(i)
        if (slack < t * (-d(i))) then
          t = slack / (-d(i))
          blocker = i
        end if
      else if (d(i) > 0.0_wp .and. self%ub(i) < big) then
        slack = self%ub(i) - x(i)
        if (slack < t * d(i)) then
          t = slack / d(i)
          blocker = i
        end if
      end if
    end do
  end subroutine box_max_step

  !> x_blocker = the bound d points to.
  subroutine box_pin(self, x, d, blocker)
    class(box_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:)         !< the direction of the step that was cut
    integer, intent(in) :: blocker       !< from max_step (0: nothing to do)
    if (blocker <= 0) return
    if (d(blocker) > 0.0_wp) then
      x(blocker) = self%ub(blocker)
    else
      x(blocker) = self%lb(blocker)
    end if
  end subroutine box_pin

  !> For each variable in turn, v = t d_i; when x_i + v crosses a finite bound, t is scaled
  !! by the fraction of v that reaches it (with whole: the step is refused instead, t
  !! unchanged). True when a cut was needed.
  logical function box_cut_step(self, x, d, t, whole) result(cut)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(inout) :: t         !< in: the step wanted; out: the feasible step
    logical, intent(in) :: whole         !< stop at the first cut, t unchanged
    real(wp) :: vj
    integer :: j
    cut = .false.
    do j = 1, size(x)
      vj = t * d(j)
      if (vj < 0.0_wp .and. self%lb(j) > -big) then
        if (x(j) + vj < self%lb(j)) then
          cut = .true.
          if (whole) return
          t = t * max(0.0_wp, (x(j) - self%lb(j)) / (-vj))
        end if
      else if (vj > 0.0_wp .and. self%ub(j) < big) then
        if (x(j) + vj > self%ub(j)) then
          cut = .true.
          if (whole) return
          t = t * max(0.0_wp, (self%ub(j) - x(j)) / vj)
        end if
      end if
    end do
  end function box_cut_step

  !> min(tmax, min_i max(0, (bound_i - x_i) / d_i)) over the variables moving towards a
  !! finite bound.
  real(wp) function box_step_bound(self, x, d, tmax) result(t)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), d(:)   !< feasible point, direction
    real(wp), intent(in) :: tmax         !< the step wanted
    real(wp) :: ti
    integer :: j
    t = tmax
    do j = 1, size(x)
      if (d(j) < 0.0_wp .and. self%lb(j) > -big) then
        ti = (self%lb(j) - x(j))/d(j)
        t = min(t, max(ti, 0.0_wp))
      else if (d(j) > 0.0_wp .and. self%ub(j) < big) then
        ti = (self%ub(j) - x(j))/d(j)
        t = min(t, max(ti, 0.0_wp))
      end if
    end do
  end function box_step_bound

  !> held(i): at lb with g_i >= 0 (or fixed), or at ub with g_i <= 0.
  subroutine box_binding(self, x, g, mask)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, gradient
    logical, intent(out) :: mask(:)      !< held
    integer :: i
    do i = 1, size(x)
      mask(i) = (x(i) <= self%lb(i) .and. (g(i) >= 0.0_wp .or. self%lb(i) == self%ub(i))) .or. &
                (x(i) >= self%ub(i) .and. g(i) <= 0.0_wp)
    end do
  end subroutine box_binding

  !> out(i): at lb with d_i < 0, or at ub with d_i > 0.
  subroutine box_leaving(self, x, g, mask)
    class(box_set_t), intent(in) :: self
    real(wp), intent(in) :: x(:), g(:)   !< iterate, direction d
    logical, intent(out) :: mask(:)      !< out
    integer :: i
    do i = 1, size(x)
      mask(i) = (x(i) <= self%lb(i) .and. g(i) < 0.0_wp) .or. (x(i) >= self%ub(i) .and. g(i) > 0.0_wp)
    end do
  end subroutine box_leaving

  !> x_j += t d_j for j in idx; a variable at or within 4 eps |t d_j| of a bound it moves
  !! to is put on that bound exactly and held.
  subroutine box_settle(self, x, d, t, idx, held)
    class(box_set_t), intent(in) :: self
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(in) :: d(:), t      !< direction, step
    integer, intent(in) :: idx(:)        !< the variables that move
    logical, intent(inout) :: held(:)    !< set where a variable lands on a bound
    integer :: i
    do i = 1, size(idx)
      associate (j => idx(i))
        x(j) = x(j) + t*d(j)
        if (x(j) <= self%lb(j) .or. (d(j) < 0.0_wp .and. (x(j) - self%lb(j)) <= 4.0_wp*epsilon(1.0_wp)*abs(t*d(j)))) then
          x(j) = self%lb(j)
          held(j) = .true.
        else if (x(j) >= self%ub(j) .or. (d(j) > 0.0_wp .and. (self%ub(j) - x(j)) <= 4.0_wp*epsilon(1.0_wp)*abs(t*d(j)))) then
          x(j) = self%ub(j)
          held(j) = .true.
        end if
      end associate
    end do
  end subroutine box_settle

end module constraint_set
