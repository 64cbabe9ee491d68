!> The active-set Newton method on the friction set of 3D contact (module tangent_discs: a
!! box on some variables, a disc |(x_a, x_b)| <= r on pairs of the others), for
!!
!!     minimise f(x) = 1/2 x'Ax - b'x   subject to   x in K,
!!
!! A symmetric positive definite and dense. A sequential quadratic programming step on the
!! current face: the box variables held on a bound stay there, a disc held on its circle
!! moves along it, the rest is free. With x_k = r_k nu_k on a held circle, tau_k its unit
!! tangent and s_k = -nu_k.g_k >= 0 the force that presses it outwards, the step on the face
!! is d = Z delta, Z the free variables and the tangents, from
!!
!!     (Z'AZ + C) delta = -Z'g,      C = diag(s_k / r_k) on the tangents,
!!
!! the Newton step of the Lagrangian on the circle (its curvature 1/r_k times the multiplier
!! s_k), exact on a flat face and quadratically convergent on a curved one. The step is cut
!! where a free variable reaches its bound or a free disc its circle (which then join the
!! held set), the held discs are projected back onto their circles, and the step is halved
!! while the cost does not fall (beyond its rounding); a cut step is replaced by the whole step
!! projected onto the set when that lowers the cost more (all its blockers then join the held
!! set in one step). Constraints are released, as in
!! module qp_newton, after a whole step (x near its face's minimiser): a box variable whose
!! multiplier has the wrong sign, a disc whose gradient points into it (nu.g > 0).
!!
!! Each step factors the face's matrix (dense Cholesky, `dpotrf_tiles`) and computes the
!! gradient afresh (one product with A; the projection makes a recurrence inexact).
!!
!! Thread safety: no module variables; the work arrays are the caller's.
module disc_newton
  use kinds, only: wp
  use lapack, only: dpotrf_tiles, dpotrs, dsymv
  use tangent_discs, only: disc_set_t, circle_point
  implicit none (type, external)
  private

  public :: disc_newton_step, disc_held
  public :: DN_STEP, DN_STILL, DN_NOT_SPD

  integer, parameter :: DN_STEP = 0       !< a step was taken
  integer, parameter :: DN_STILL = 1      !< no step: x is its face's minimiser and nothing is released
  integer, parameter :: DN_NOT_SPD = 2    !< the face's matrix is not positive definite (A is not SPD)
  integer, parameter :: MAX_HALVING = 40

contains

  !> held(i): box variable i on a bound with its gradient pointing out of the box (the
  !! box's `binding`); both variables of a disc on its circle with nu.g <= 0.
  subroutine disc_held(set, x, g, held)
    type(disc_set_t), intent(in) :: set
    real(wp), intent(in) :: x(:), g(:)
    logical, intent(out) :: held(:)
    call set%binding(x, g, held)
  end subroutine disc_held

  !> One step from the feasible x with g = A x - b (both updated; ax = A x too). held is the
  !! working set (disc_held at the start of a solve, then carried); at_min: the last step was
  !! whole (x near its face's minimiser): release first. flops: the step's work; factored:
  !! counts the face factorizations.
  subroutine disc_newton_step(a, b, set, x, g, ax, held, at_min, outcome, flops, factored)
    real(wp), intent(in) :: a(:, :)           !< A (n x n, dense, symmetric)
    real(wp), intent(in) :: b(:)              !< the linear term
    type(disc_set_t), intent(in) :: set       !< the feasible set
    real(wp), intent(inout) :: x(:)           !< feasible iterate
    real(wp), intent(inout) :: g(:)           !< A x - b
    real(wp), intent(inout) :: ax(:)          !< A x
    logical, intent(inout) :: held(:)         !< the working set (see above)
    logical, intent(inout) :: at_min          !< in: release first; out: this step was whole
    integer, intent(out) :: outcome           !< DN_*
    real(wp), intent(inout) :: flops          !< work added (multiply-adds x 2)
    integer, intent(inout) :: factored        !< factorizations made (one more when this step made one)
    integer, allocatable :: free(:), dk(:)
    real(wp), allocatable :: h(:, :), rhs(:), tau(:, :), curv(:), d(:), dfree(:), x0(:), g0(:), xb(:), axb(:)
    logical, allocatable :: rel(:), onb(:)
    integer :: n, nf, nd, k, i, j, info, blk, half, q
    real(wp) :: t, tmax, df, noise, s, na, nb
    logical :: cut
    n = size(x)
    outcome = DN_STEP
    ! 1. releases at a face's minimiser
    if (at_min) then
      allocate (rel(n))
      call set%binding(x, g, rel)
      held = held .and. rel
    end if
    ! 2. the face: free variables (not held, box or disc) and the held discs' tangents
    free = pack([(i, i=1, n)], .not. held)
    nf = size(free)
    dk = pack([(k, k=1, size(set%r))], [(held(set%pair(1, k)) .and. set%r(k) > 0.0_wp, k=1, size(set%r))])
    nd = size(dk)
    if (nf + nd == 0) then
      outcome = DN_STILL
      at_min = .true.
      return
    end if
    allocate (tau(2, nd), curv(nd))
    do q = 1, nd
      k = dk(q)
      call circle_point(x(set%pair(1, k)), x(set%pair(2, k)), na, nb, s)
      tau(:, q) = [-nb, na]
      curv(q) = max(-(na*g(set%pair(1, k)) + nb*g(set%pair(2, k))), 0.0_wp)/set%r(k)
    end do
    allocate (h(nf + nd, nf + nd), rhs(nf + nd))
    do j = 1, nf
      do i = j, nf
        h(i, j) = a(free(i), free(j))
      end do
      do q = 1, nd
        h(nf + q, j) = tau(1, q)*a(set%pair(1, dk(q)), free(j)) + tau(2, q)*a(set%pair(2, dk(q)), free(j))
      end do
      rhs(j) = -g(free(j))
    end do
    do q = 1, nd
      associate (p1 => set%pair(1, dk(q)), p2 => set%pair(2, dk(q)))
        do i = q, nd
          associate (r1 => set%pair(1, dk(i)), r2 => set%pair(2, dk(i)))
            h(nf + i, nf + q) = tau(1, i)*(a(r1, p1)*tau(1, q) + a(r1, p2)*tau(2, q)) + &
                                tau(2, i)*(a(r2, p1)*tau(1, q) + a(r2, p2)*tau(2, q))
          end associate
        end do
        h(nf + q, nf + q) = h(nf + q, nf + q) + curv(q)
        rhs(nf + q) = -(tau(1, q)*g(p1) + tau(2, q)*g(p2))
      end associate
    end do
    call dpotrf_tiles('L', nf + nd, h, nf + nd, info)
    flops = flops + real(nf + nd, wp)**3/3.0_wp
    factored = factored + 1
    if (info /= 0) then
      outcome = DN_NOT_SPD
      return
    end if
    call dpotrs('L', nf + nd, 1, h, nf + nd, rhs, nf + nd, info)
    flops = flops + 2.0_wp*real(nf + nd, wp)**2
    allocate (d(n), dfree(n))
    d = 0.0_wp
    d(free) = rhs(1:nf)
    dfree = d
    do q = 1, nd
      d(set%pair(:, dk(q))) = rhs(nf + q)*tau(:, q)
    end do
    if (all(d == 0.0_wp) .or. norm2(d) <= epsilon(1.0_wp)*norm2(x)) then
      outcome = DN_STILL
      at_min = .true.
      return
    end if
    ! 3. the feasible step of the free variables (the held discs turn, they are not cut)
    call set%max_step(x, dfree, 1.0_wp, tmax, blk)
    tmax = max(tmax, 0.0_wp)
    t = tmax
    x0 = x
    g0 = g
    cut = blk /= 0
    do half = 0, MAX_HALVING
      x = x0 + t*d
      call set%project(x)
      if (cut .and. half == 0) call set%pin(x, dfree, blk)
      call dsymv('U', n, 1.0_wp, a, n, x, 1, 0.0_wp, ax, 1)
      g = ax - b
      ! an increase below its rounding counts as none (the two gradients' over the step,
      ! the projected point's eps |x| against the gradient)
      df = 0.5_wp*dot_product(g0 + g, x - x0)
      noise = 8.0_wp*epsilon(1.0_wp)*(dot_product(abs(ax) + abs(b), abs(x - x0)) + dot_product(abs(g0) + abs(g), abs(x)))
      if (df <= noise) exit
      t = 0.5_wp*t
    end do
    flops = flops + 2.0_wp*real(n, wp)**2*real(min(half, MAX_HALVING) + 1, wp)
    if (half > MAX_HALVING) then
      x = x0
      g = g0
      ax = g0 + b
      outcome = DN_STILL
      at_min = .true.
      return
    end if
    ! the blocker joins the held set (a disc: both variables)
    if (cut .and. half == 0) then
      if (set%disc(blk) > 0) then
        held(set%pair(:, set%disc(blk))) = .true.
      else
        held(blk) = .true.
      end if
      ! the whole step projected onto the set, taken instead when it lowers the cost more:
      ! every variable and disc it takes beyond its bound joins the held set at once, not one
      ! per step (a warm start whose face moved by many discs); one more product
      xb = x0 + d
      call set%project(xb)
      allocate (axb(n), onb(n))
      call dsymv('U', n, 1.0_wp, a, n, xb, 1, 0.0_wp, axb, 1)
      flops = flops + 2.0_wp*real(n, wp)**2
      if (0.5_wp*dot_product(xb, axb) - dot_product(b, xb) < 0.5_wp*dot_product(x, ax) - dot_product(b, x)) then
        x = xb
        ax = axb
        g = ax - b
        call set%free_mask(x, onb)
        held = held .or. .not. onb
      end if
    end if
    at_min = .not. cut .and. half == 0
  end subroutine disc_newton_step

end module disc_newton
