!> The parts of MPRGP (module mprgp) that work on plain vectors: the power iteration for
!! lambda_max, the norm of the projected gradient, and the steps that cost no product with
!! A because the images of their directions are known: an exact line search, and the
!! Galerkin step over a ring of stored A-normalised directions (Krylov recycling) with the
!! ring's upkeep. The constraints are one `class(constraint_set_t)` (module constraint_set:
!! projection, free set, chopped gradient, step cut).
module mprgp_support
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use linop, only: linop_t
  use constraint_set, only: constraint_set_t
  implicit none (type, external)
  private

  public :: lambda_max_estimate, power_iteration, line_search, recycled_subspace, store_direction

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


  !> Exact line search from x along d (A d is given: no product), cut at the bounds, with
  !! the gradient g updated alike; with `whole`, only the whole step, and only if it leaves
  !! a smaller projected gradient and a proportional iterate (|chopped|^2 <= Gamma^2
  !! |free|^2): otherwise MPRGP would first release bounds and redo what the step did
  !! (delta = 1 cycles). True when x moved.
  logical function line_search(x, g, set, d, ad, whole, gamma, p, ap) result(moved)
    real(wp), intent(inout) :: x(:)      !< iterate
    real(wp), intent(inout) :: g(:)      !< A x - b
    class(constraint_set_t), intent(in) :: set   !< the constraints
    real(wp), intent(in) :: d(:), ad(:)  !< direction and A d
    logical, intent(in) :: whole         !< the whole step or none
    real(wp), intent(in) :: gamma        !< proportioning constant Gamma
    real(wp), intent(inout) :: p(:), ap(:)   !< work (size n)
    integer :: j, n
    real(wp) :: dad_, t, gp_before, gp_after, bb_after
    real(wp), allocatable :: beta(:)
    logical, allocatable :: free(:)
    logical :: cut
    moved = .false.
    n = size(x)
    dad_ = dot_product(d, ad)
    if (.not. (dad_ > 0.0_wp .and. ieee_is_finite(dad_))) return
    t = -dot_product(g, d) / dad_
    if (.not. ieee_is_finite(t)) return
    cut = set%cut_step(x, d, t, whole)
    if (cut .and. whole) return
    if (t == 0.0_wp) return
    if (whole) then
      gp_before = set%projected_gradient_norm(x, g)
      do j = 1, n
        p(j) = x(j) + t * d(j)
        ap(j) = g(j) + t * ad(j)
      end do
      call set%project(p)
      allocate (free(n), beta(n))
      call set%free_mask(p, free)
      call set%chopped_gradient(p, ap, beta)
      gp_after = 0.0_wp
      bb_after = 0.0_wp
      do j = 1, n
        if (free(j)) then
          gp_after = gp_after + ap(j)**2
        else
          bb_after = bb_after + beta(j)**2
        end if
      end do
      if (.not. (sqrt(gp_after + bb_after) < gp_before .and. bb_after <= gamma**2 * gp_after)) return
      x = p
      g = ap
    else
      do j = 1, n
        x(j) = x(j) + t * d(j)
        g(j) = g(j) + t * ad(j)
      end do
      call set%project(x)
    end if
    moved = .true.
  end function line_search

  !> The minimum over x plus the span of s and of the first nrw stored directions that
  !! vanish where x is at a bound (no product: all the images under A are known), taken
  !! only if the whole Galerkin step is feasible (a step cut at a bound would fix variables
  !! that belong to the free set) and helps (`line_search`). A direction keeps its place
  !! only if at least 1e-4 of its A-norm squared is left after the A-orthogonalisation: the
  !! rounding of its image then stays within 100 times that of a product. True when x moved.
  logical function recycled_subspace(x, g, set, rw, raw, nrw, gamma, v, av, p, ap, s, as) result(moved)
    real(wp), intent(inout) :: x(:)             !< iterate
    real(wp), intent(inout) :: g(:)             !< A x - b
    class(constraint_set_t), intent(in) :: set  !< the constraints
    real(wp), intent(in) :: rw(:, :), raw(:, :) !< stored directions and their images
    integer, intent(in) :: nrw                  !< directions held in rw
    real(wp), intent(in) :: gamma               !< proportioning constant Gamma
    real(wp), intent(inout) :: v(:), av(:), p(:), ap(:)   !< work (size n)
    real(wp), intent(in), optional :: s(:), as(:)         !< one more direction and A s
    real(wp), allocatable :: q(:, :), aq(:, :)
    integer :: j, l, k, pass
    real(wp) :: c, d0, dn
    logical, allocatable :: free(:)
    moved = .false.
    allocate (q(size(x), nrw + 1), aq(size(x), nrw + 1), free(size(x)))
    call set%free_mask(x, free)
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
      if (any(v /= 0.0_wp .and. .not. free)) cycle
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
    moved = line_search(x, g, set, v, av, .true., gamma, p, ap)
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
