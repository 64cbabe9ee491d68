!> The parts of MPRGP (module mprgp) that work on plain vectors: the power iteration for
!! lambda_max, the norm of the projected gradient, and the steps that cost no product with
!! A because the images of their directions are known: an exact line search, and the
!! Galerkin step over a ring of stored A-normalised directions (Krylov recycling) with the
!! ring's upkeep. Box bounds lb <= x <= ub: a lower bound -huge(1.0_wp) or an upper bound
!! +huge(1.0_wp) means "no bound"; x_i is free when lb_i < x_i < ub_i, at its lower bound
!! when x_i <= lb_i < ub_i, at its upper bound when x_i >= ub_i > lb_i, and fixed when
!! lb_i = ub_i. The upper-bound branches are never taken when ub = +huge, so a lower-bound
!! problem executes the same floating-point operations as without ub.
module mprgp_support
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use linop, only: linop_t
  implicit none (type, external)
  private

  public :: lambda_max_estimate, power_iteration, projected_gradient_norm, line_search, recycled_subspace, &
            store_direction, chopped

contains

  !> Estimate of the largest eigenvalue of the SPD operator A by `its` power
  !! iterations from a fixed pseudo-random start vector (deterministic).
  !! Returns max_k |A v_k| with |v_k| = 1: a lower bound of lambda_max (for symmetric
  !! A), usually within a few percent after 20 iterations. Returns 0 when n = 0 or
  !! A v = 0; a non-finite value if A produced one. its < 1 is treated as 1.
  function lambda_max_estimate(A, its, nmv) result(lam)
    class(linop_t), intent(inout) :: A      !< the operator
    integer, intent(in) :: its              !< number of power iterations (products with A)
    integer, intent(out), optional :: nmv   !< products with A performed
    real(wp) :: lam
    real(wp), allocatable :: v(:), w(:)
    integer :: k
    allocate (v(max(A%n, 0)), w(max(A%n, 0)))
    call power_iteration(A, its, v, w, lam, k)
    if (present(nmv)) nmv = k
  end function lambda_max_estimate

  !> Power iteration with caller-provided work vectors v, w (size n).
  subroutine power_iteration(A, its, v, w, lam, nmv)
    class(linop_t), intent(inout) :: A       !< the operator
    integer, intent(in) :: its               !< power iterations (at least 1)
    real(wp), intent(inout) :: v(:), w(:)    !< work
    real(wp), intent(out) :: lam             !< max_k |A v_k|
    integer, intent(out) :: nmv              !< products with A
    integer :: i, k, n
    integer, parameter :: i8k = selected_int_kind(18)
    integer(i8k) :: s
    real(wp) :: nw
    n = A%n
    lam = 0.0_wp
    nmv = 0
    if (n <= 0) return
    ! Park-Miller minimal standard generator: deterministic, local state, no overflow.
    s = 12345_i8k
    do i = 1, n
      s = mod(16807_i8k * s, 2147483647_i8k)
      v(i) = real(s, wp) / 2147483647.0_wp - 0.5_wp
    end do
    v(1:n) = v(1:n) / norm2(v(1:n))
    do k = 1, max(its, 1)
      call A%apply(v(1:n), w(1:n))
      nmv = nmv + 1
      nw = norm2(w(1:n))
      if (.not. ieee_is_finite(nw)) then
        lam = nw
        return
      end if
      lam = max(lam, nw)
      if (nw <= 0.0_wp) return
      v(1:n) = w(1:n) / nw
    end do
  end subroutine power_iteration


  !> The chopped gradient of one variable off the free set: min(g, 0) at its lower bound,
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

  !> |gP|: the norm of g on the free variables and of the chopped gradient on the others.
  real(wp) function projected_gradient_norm(g, x, lb, ub) result(r)
    real(wp), intent(in) :: g(:)    !< gradient
    real(wp), intent(in) :: x(:)    !< iterate
    real(wp), intent(in) :: lb(:)   !< lower bounds
    real(wp), intent(in) :: ub(:)   !< upper bounds
    integer :: j
    r = 0.0_wp
    do j = 1, size(x)
      r = r + chopped(g(j), x(j), lb(j), ub(j))**2
    end do
    r = sqrt(r)
  end function projected_gradient_norm

  !> Exact line search from x along d (A d is given: no product), cut at the bounds, with
  !! the gradient g updated alike; with `whole`, only the whole step, and only if it leaves
  !! a smaller projected gradient and a proportional iterate (|chopped|^2 <= Gamma^2
  !! |free|^2): otherwise MPRGP would first release bounds and redo what the step did
  !! (delta = 1 cycles). True when x moved.
  logical function line_search(x, g, lb, ub, d, ad, whole, gamma, p, ap) result(moved)
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(inout) :: g(:)      !< A x - b
    real(wp), intent(in) :: lb(:)        !< lower bounds
    real(wp), intent(in) :: ub(:)        !< upper bounds
    real(wp), intent(in) :: d(:), ad(:)  !< direction and A d
    logical, intent(in) :: whole         !< the whole step or none
    real(wp), intent(in) :: gamma        !< proportioning constant Gamma
    real(wp), intent(inout) :: p(:), ap(:)   !< work (size n)
    real(wp), parameter :: big = huge(1.0_wp)
    integer :: j, n
    real(wp) :: dad_, t, vj, gp_before, gp_after, bb_after
    moved = .false.
    n = size(x)
    dad_ = dot_product(d, ad)
    if (.not. (dad_ > 0.0_wp .and. ieee_is_finite(dad_))) return
    t = -dot_product(g, d) / dad_
    if (.not. ieee_is_finite(t)) return
    do j = 1, n
      vj = t * d(j)
      if (vj < 0.0_wp .and. lb(j) > -big) then
        if (x(j) + vj < lb(j)) then
          if (whole) return
          t = t * max(0.0_wp, (x(j) - lb(j)) / (-vj))
        end if
      else if (vj > 0.0_wp .and. ub(j) < big) then
        if (x(j) + vj > ub(j)) then
          if (whole) return
          t = t * max(0.0_wp, (ub(j) - x(j)) / vj)
        end if
      end if
    end do
    if (t == 0.0_wp) return
    if (whole) then
      gp_before = projected_gradient_norm(g, x, lb, ub)
      do j = 1, n
        p(j) = min(max(x(j) + t * d(j), lb(j)), ub(j))
        ap(j) = g(j) + t * ad(j)
      end do
      gp_after = 0.0_wp
      bb_after = 0.0_wp
      do j = 1, n
        if (p(j) > lb(j) .and. p(j) < ub(j)) then
          gp_after = gp_after + ap(j)**2
        else
          bb_after = bb_after + chopped(ap(j), p(j), lb(j), ub(j))**2
        end if
      end do
      if (.not. (sqrt(gp_after + bb_after) < gp_before .and. bb_after <= gamma**2 * gp_after)) return
      x = p
      g = ap
    else
      do j = 1, n
        x(j) = min(max(x(j) + t * d(j), lb(j)), ub(j))
        g(j) = g(j) + t * ad(j)
      end do
    end if
    moved = .true.
  end function line_search

  !> The minimum over x plus the span of s and of the first nrw stored directions that
  !! vanish where x is at a bound (no product: all the images under A are known), taken
  !! only if the whole Galerkin step is feasible (a step cut at a bound would fix variables
  !! that belong to the free set) and helps (`line_search`). A direction keeps its place
  !! only if at least 1e-4 of its A-norm squared is left after the A-orthogonalisation: the
  !! rounding of its image then stays within 100 times that of a product. True when x moved.
  logical function recycled_subspace(x, g, lb, ub, rw, raw, nrw, gamma, v, av, p, ap, s, as) result(moved)
    real(wp), intent(inout) :: x(:)             !< iterate
    real(wp), intent(inout) :: g(:)             !< A x - b
    real(wp), intent(in) :: lb(:)               !< lower bounds
    real(wp), intent(in) :: ub(:)               !< upper bounds
    real(wp), intent(in) :: rw(:, :), raw(:, :) !< stored directions and their images
    integer, intent(in) :: nrw                  !< directions held in rw
    real(wp), intent(in) :: gamma               !< proportioning constant Gamma
    real(wp), intent(inout) :: v(:), av(:), p(:), ap(:)   !< work (size n)
    real(wp), intent(in), optional :: s(:), as(:)         !< one more direction and A s
    real(wp), allocatable :: q(:, :), aq(:, :)
    integer :: j, l, k, pass
    real(wp) :: c, d0, dn
    moved = .false.
    allocate (q(size(x), nrw + 1), aq(size(x), nrw + 1))
    k = 0
    do j = 0, nrw
      if (j == 0) then
        if (.not. present(s)) cycle
        v = s
        av = as
      else
        v = rw(:, j)
        av = raw(:, j)
      end if
      if (any(v /= 0.0_wp .and. (x <= lb .or. x >= ub))) cycle
      d0 = dot_product(v, av)
      if (.not. (d0 > 0.0_wp .and. ieee_is_finite(d0))) cycle
      do pass = 1, 2
        do l = 1, k
          c = dot_product(aq(:, l), v)
          v = v - c * q(:, l)
          av = av - c * aq(:, l)
        end do
      end do
      dn = dot_product(v, av)
      if (.not. (dn > 1.0e-4_wp * d0 .and. ieee_is_finite(dn))) cycle
      k = k + 1
      q(:, k) = v / sqrt(dn)
      aq(:, k) = av / sqrt(dn)
    end do
    if (k == 0) return
    v = 0.0_wp
    av = 0.0_wp
    do l = 1, k
      c = -dot_product(g, q(:, l))
      v = v + c * q(:, l)
      av = av + c * aq(:, l)
    end do
    moved = line_search(x, g, lb, ub, v, av, .true., gamma, p, ap)
  end function recycled_subspace

  !> Keep the direction d (with A d), A-normalised, in the ring rw, raw (the oldest makes
  !! room when it is full).
  subroutine store_direction(d, ad, rw, raw, nrw)
    real(wp), intent(in) :: d(:), ad(:)              !< direction and A d
    real(wp), intent(inout) :: rw(:, :), raw(:, :)   !< the ring: directions and images
    integer, intent(inout) :: nrw(2)                 !< directions held, next slot to fill
    integer :: k
    real(wp) :: d0
    k = size(rw, 2)
    if (k == 0) return
    d0 = dot_product(d, ad)
    if (.not. (d0 > 0.0_wp .and. ieee_is_finite(d0))) return
    d0 = 1.0_wp / sqrt(d0)
    rw(:, nrw(2)) = d0 * d
    raw(:, nrw(2)) = d0 * ad
    nrw(1) = min(nrw(1) + 1, k)
    nrw(2) = mod(nrw(2), k) + 1
  end subroutine store_direction

end module mprgp_support
