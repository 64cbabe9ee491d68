!> The step of the active-set Newton method for the bound-constrained convex QP
!!
!!     minimise f(x) = 1/2 x'Ax - b'x   subject to   l <= x <= u
!!
!! with A symmetric positive definite and dense (n up to a few thousand): a primal
!! active-set method whose face problems are solved exactly by a dense Cholesky factor
!! (J. Nocedal and S. J. Wright, "Numerical Optimization", 2nd ed., Springer 2006, sec. 16.5;
!! Z. Dostal, "Optimal Quadratic Programming Algorithms", Springer 2009, sec. 5.2), with
!! constraints added and released in blocks.
!!
!! The working set W holds variables at a bound; F is the rest. One step from a feasible x
!! with g = Ax - b:
!!   1. when the last step reached the minimiser of f on its face, every variable of W whose
!!      multiplier has the wrong sign (g_i < 0 at l_i, g_i > 0 at u_i) leaves W;
!!   2. the Newton direction on the face: A_FF d_F = -g_F, d_W = 0, by a dense Cholesky
!!      factor of A_FF (LAPACK dpotrf; a free block that is not numerically positive
!!      definite is shifted by tau I, tau growing from 1e-14 of its largest diagonal, which
!!      keeps d a direction of descent);
!!   3. the longest feasible step along d up to 1: a whole step reaches the face's
!!      minimiser; a shorter one stops where variables reach their bounds, and those join W
!!      (exactly on their bounds).
!! f decreases at every step (d is a descent direction of the face after a release), and
!! a face's minimiser is reached at most once, so the method ends after finitely many
!! steps; on the right face a step is exact, so the work does not grow with the condition
!! number of A (a Cholesky solve is backward stable: the gradient it leaves is at the
!! rounding level of A x). Initial W: the variables of the warm start at a bound whose
!! gradient does not point into the box.
!!
!! The bounds are one `class(constraint_set_t)` (module constraint_set): the working set is
!! what its `binding` test holds, the step length its `step_bound`, the landing on the
!! boundary its `settle`; the method itself is that of a box, whose faces are flat.
!!
!! The caller (module mprgp) runs the steps, tests convergence on the projected gradient
!! and counts the work.
!!
!! Thread safety: no module variables; each solve has its own work arrays.
module qp_newton
  use kinds, only: wp
  use lapack, only: dpotrf, dpotrs, dsymv
  use constraint_set, only: constraint_set_t
  implicit none (type, external)
  private

  public :: newton_work_t, newton_step
  public :: NEWTON_FULL, NEWTON_CUT, NEWTON_STILL, NEWTON_NOT_SPD

  integer, parameter :: NEWTON_FULL = 0      !< a whole step: x is the minimiser of f on its face
  integer, parameter :: NEWTON_CUT = 1       !< a step cut where variables reached their bounds (they joined W)
  integer, parameter :: NEWTON_STILL = 3     !< d = 0: x is its face's minimiser and no multiplier has the wrong sign
  integer, parameter :: NEWTON_NOT_SPD = 4   !< a diagonal entry <= 0 or a curvature <= 0: A is not SPD

  integer, parameter :: SHIFT_TRIES = 8      !< shifts of a free block that is not numerically SPD

  !> Work arrays and the working set of one solve (allocated on first use, sized n).
  type :: newton_work_t
    real(wp), allocatable :: h(:, :)        !< the free block and its Cholesky factor
    real(wp), allocatable :: d(:), ad(:), rhs(:)
    logical, allocatable :: held(:)         !< the working set: the variables held on the boundary
    integer, allocatable :: free(:)         !< the free variables of the last step
    logical, allocatable :: rel(:)          !< the variables released by this step
    logical, allocatable :: mask(:)         !< work: the set's binding / leaving test
    integer :: nfree = 0                    !< their number
    logical :: started = .false.            !< the working set was taken from the warm start
    logical :: at_min = .false.             !< the last step reached its face's minimiser
    !> the last step solved the face of the step before without a release: two whole steps
    !! in a row on one face leave x at its minimiser to working precision
    logical :: same_face = .false.
    integer :: shifts = 0                   !< steps whose free block needed a shift
  end type newton_work_t

contains

  !> One step of the method (module header). x, g = A x - b and ax = A x are updated
  !! together (g and ax by the recurrence g + t A d). outcome: NEWTON_*; flops: the
  !! floating-point operations the step made (factor, solves and products).
  subroutine newton_step(a, set, x, g, ax, work, outcome, flops)
    real(wp), intent(in) :: a(:, :)         !< (n, n) SPD, both triangles stored
    class(constraint_set_t), intent(in) :: set   !< the bounds
    real(wp), intent(inout) :: x(:)         !< feasible iterate
    real(wp), intent(inout) :: g(:)         !< A x - b at x
    real(wp), intent(inout) :: ax(:)        !< A x at x
    type(newton_work_t), intent(inout) :: work
    integer, intent(out) :: outcome
    real(wp), intent(out) :: flops
    integer :: n, i, nf, info, try, nrel, worst
    real(wp) :: dad, t, dmax, tau, wmax

    n = size(x)
    flops = 0.0_wp
    call ensure_work(work, n)
    do i = 1, n
      if (a(i, i) <= 0.0_wp) then
        outcome = NEWTON_NOT_SPD
        return
      end if
    end do
    ! 1. the working set: from the warm start, or the release of wrong multipliers
    nrel = 0
    if (.not. work%started) then
      call set%binding(x, g, work%held)
      work%started = .true.
      work%at_min = .false.
    else if (work%at_min) then
      ! the wrong multipliers leave W (a fixed variable never does); the most wrong (scaled:
      ! |g_i| / sqrt(a_ii)) is kept in mind
      worst = 0
      wmax = 0.0_wp
      call set%binding(x, g, work%mask)
      do i = 1, n
        if (work%held(i) .and. .not. work%mask(i)) then
          work%rel(i) = .true.
          work%held(i) = .false.
          nrel = nrel + 1
          if (abs(g(i))/sqrt(a(i, i)) > wmax) then
            wmax = abs(g(i))/sqrt(a(i, i))
            worst = i
          end if
        end if
      end do
    end if
    work%same_face = work%at_min .and. nrel == 0
    ! 2. the Newton direction on the face. A block release whose direction would take a
    !    released variable out of the box (a step of length 0) is narrowed to the most wrong
    !    multiplier alone, whose direction always points into the box.
    call direction()
    if (outcome == NEWTON_NOT_SPD) return
    if (nrel > 1 .and. outcome /= NEWTON_STILL) then
      call set%leaving(x, work%d, work%mask)
      if (any(work%rel .and. work%mask)) then
        do i = 1, n
          if (work%rel(i) .and. i /= worst) work%held(i) = .true.
        end do
        call direction()
        if (outcome == NEWTON_NOT_SPD) return
      end if
    end if
    work%rel = .false.
    if (outcome == NEWTON_STILL) return
    nf = work%nfree
    ! 3. the longest feasible step up to 1
    t = set%step_bound(x, work%d, 1.0_wp)
    call dsymv('U', n, 1.0_wp, a, n, work%d, 1, 0.0_wp, work%ad, 1)
    flops = flops + 2.0_wp*real(n, wp)**2
    dad = dot_product(work%d, work%ad)
    if (dad <= 0.0_wp) then
      outcome = NEWTON_NOT_SPD
      return
    end if
    work%at_min = t >= 1.0_wp
    outcome = merge(NEWTON_FULL, NEWTON_CUT, work%at_min)
    ! the variables that reach a bound (to rounding) join the working set, on it exactly
    call set%settle(x, work%d, t, work%free(1:nf), work%held)
    g = g + t*work%ad
    ax = ax + t*work%ad

  contains

    !> d on the face of the variables not held (outcome NEWTON_CUT until the step is taken,
    !! NEWTON_STILL when d vanishes, NEWTON_NOT_SPD when no shift makes A_FF positive definite).
    subroutine direction()
      integer :: k
      outcome = NEWTON_CUT
      nf = 0
      do k = 1, n
        if (work%held(k)) cycle
        nf = nf + 1
        work%free(nf) = k
      end do
      work%nfree = nf
      work%d = 0.0_wp
      if (nf == 0) then
        outcome = NEWTON_STILL
        work%at_min = .true.
        return
      end if
      dmax = 0.0_wp
      do k = 1, nf
        dmax = max(dmax, a(work%free(k), work%free(k)))
      end do
      tau = 0.0_wp
      do try = 0, SHIFT_TRIES
        call gather_block(a, work%free(1:nf), tau, work%h)
        call dpotrf('L', nf, work%h, n, info)
        flops = flops + real(nf, wp)**3/3.0_wp
        if (info == 0) exit
        tau = merge(1.0e-14_wp*dmax, 100.0_wp*tau, try == 0)
      end do
      if (info /= 0) then
        outcome = NEWTON_NOT_SPD
        return
      end if
      if (tau > 0.0_wp) work%shifts = work%shifts + 1
      do k = 1, nf
        work%rhs(k) = -g(work%free(k))
      end do
      call dpotrs('L', nf, 1, work%h, n, work%rhs, n, info)
      flops = flops + 2.0_wp*real(nf, wp)**2
      do k = 1, nf
        work%d(work%free(k)) = work%rhs(k)
      end do
      ! a step below the rounding of x: x is the face's minimiser to working precision
      if (norm2(work%d) <= epsilon(1.0_wp)*norm2(x) .or. all(work%d == 0.0_wp)) then
        work%d = 0.0_wp
        outcome = NEWTON_STILL
        work%at_min = .true.
        return
      end if
    end subroutine direction

  end subroutine newton_step

  !> h(1:k, 1:k) = A(idx, idx) + tau I (lower triangle).
  pure subroutine gather_block(a, idx, tau, h)
    real(wp), intent(in) :: a(:, :), tau
    integer, intent(in) :: idx(:)
    real(wp), intent(inout) :: h(:, :)
    integer :: i, j
    do j = 1, size(idx)
      do i = j, size(idx)
        h(i, j) = a(idx(i), idx(j))
      end do
      h(j, j) = h(j, j) + tau
    end do
  end subroutine gather_block

  !> Work arrays of size n (kept between the steps of one solve).
  subroutine ensure_work(work, n)
    type(newton_work_t), intent(inout) :: work
    integer, intent(in) :: n
    if (allocated(work%d)) then
      if (size(work%d) == n) return
      deallocate (work%h, work%d, work%ad, work%rhs, work%held, work%free, work%rel, work%mask)
    end if
    allocate (work%h(max(1, n), max(1, n)), work%d(n), work%ad(n), work%rhs(max(1, n)), work%free(n))
    allocate (work%held(n), work%rel(n), work%mask(n), source=.false.)
    work%nfree = 0
    work%shifts = 0
    work%started = .false.
    work%at_min = .false.
  end subroutine ensure_work

end module qp_newton
