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
  use lapack, only: dpotrf_tiles, dpotrs, dsymv, dtrsv
  use constraint_set, only: constraint_set_t
  implicit none (type, external)
  private

  public :: newton_work_t, newton_step, newton_begin, chol_delete, chol_append
  public :: newton_factor, newton_forget, newton_holds
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
    !> the free set whose factor h holds, in the factor's order (fac_nf < 0: none), and its
    !! shift: a step on the same free set of the same A takes it as it is (the factor it
    !! would compute again); a free set a few variables away, an unshifted factor updated
    !! (chol_delete, chol_append)
    integer, allocatable :: fac_free(:)
    integer, allocatable :: fac_pos(:)      !< position of each variable in fac_free (0: not in it)
    integer :: fac_nf = -1
    real(wp) :: fac_tau = 0.0_wp
    integer :: fac_updates = 0              !< variables added or removed since the factor was made
    integer :: factored = 0                 !< factorizations made (a count that only grows)
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
    integer :: n, i, nf, info, nrel, worst
    logical :: definite
    real(wp) :: dad, t, wmax

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
      if (work%fac_nf >= 0) then
        if (kept_factor()) then
          if (work%fac_tau > 0.0_wp) work%shifts = work%shifts + 1
          call solve_face()
          return
        end if
      end if
      call newton_factor(a, work%free(1:nf), work, definite, flops)
      if (.not. definite) then
        outcome = NEWTON_NOT_SPD
        return
      end if
      if (work%fac_tau > 0.0_wp) work%shifts = work%shifts + 1
      call solve_face()
    end subroutine direction

    !> The kept factor brought to the free set work%free(1:nf): true when it is that set's
    !! already, or after updates (the variables that left it deleted, the last first; those
    !! that joined appended); false when it is too far (more changes than nf/12 at once, as
    !! dear as a new factor, or over nf/4 since it was made), shifted, or an appended pivot
    !! is not clearly positive (a new factor then decides).
    logical function kept_factor() result(ok)
      integer :: k, nrem, nadd, p, q
      integer, allocatable :: rem(:)
      real(wp) :: piv
      ok = .false.
      nadd = count(work%fac_pos(work%free(1:nf)) == 0)
      nrem = work%fac_nf - (nf - nadd)
      if (nadd + nrem == 0) then
        ok = .true.
        return
      end if
      if (work%fac_tau > 0.0_wp .or. 12*(nadd + nrem) > nf .or. 4*(work%fac_updates + nadd + nrem) > nf) return
      ! deletions, from the last position down (the positions above stay valid)
      rem = pack(work%fac_pos(work%fac_free(1:work%fac_nf)), work%held(work%fac_free(1:work%fac_nf)))
      do k = size(rem), 1, -1
        p = work%fac_nf
        call chol_delete(work%h, p, rem(k))
        flops = flops + 4.0_wp*real(p - rem(k), wp)**2
        work%fac_pos(work%fac_free(rem(k))) = 0
        work%fac_free(rem(k):p - 1) = work%fac_free(rem(k) + 1:p)
        work%fac_nf = p - 1
      end do
      work%fac_pos(work%fac_free(1:work%fac_nf)) = [(k, k=1, work%fac_nf)]
      ! additions, each a new last row
      do k = 1, nf
        q = work%free(k)
        if (work%fac_pos(q) > 0) cycle
        p = work%fac_nf
        call chol_append(a, work%fac_free(1:p), q, work%h, piv)
        flops = flops + real(p, wp)**2 + 2.0_wp*real(p, wp)
        if (.not. piv > 1.0e-8_wp*a(q, q)) return
        work%fac_nf = p + 1
        work%fac_free(p + 1) = q
        work%fac_pos(q) = p + 1
      end do
      work%fac_updates = work%fac_updates + nadd + nrem
      ok = .true.
    end function kept_factor

    !> d_F from the factor of A_FF (+ tau I) in h, in the factor's order.
    subroutine solve_face()
      integer :: k
      do k = 1, nf
        work%rhs(k) = -g(work%fac_free(k))
      end do
      call dpotrs('L', nf, 1, work%h, n, work%rhs, n, info)
      flops = flops + 2.0_wp*real(nf, wp)**2
      do k = 1, nf
        work%d(work%fac_free(k)) = work%rhs(k)
      end do
      ! a step below the rounding of x: x is the face's minimiser to working precision
      if (norm2(work%d) <= epsilon(1.0_wp)*norm2(x) .or. all(work%d == 0.0_wp)) then
        work%d = 0.0_wp
        outcome = NEWTON_STILL
        work%at_min = .true.
        return
      end if
    end subroutine solve_face

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

  !> The factor LAPACK makes of A(idx, idx) (idx ascending, the free set), shifted by tau I
  !! when it is not numerically positive definite (tau from 1e-14 of its largest diagonal,
  !! times 100 each try), kept in `work` (definite false: no shift helped, none kept, an
  !! outcome of the step, NEWTON_NOT_SPD, not a failure); flops grows by its cost.
  !! Deterministic: the same A and idx give the same bits.
  subroutine newton_factor(a, idx, work, definite, flops)
    real(wp), intent(in) :: a(:, :)
    integer, intent(in) :: idx(:)
    type(newton_work_t), intent(inout) :: work
    logical, intent(out) :: definite
    real(wp), intent(inout) :: flops
    integer :: nf, k, try, info
    real(wp) :: dmax, tau
    call ensure_work(work, size(a, 1))
    call newton_forget(work)
    nf = size(idx)
    definite = .true.
    if (nf == 0) return
    dmax = 0.0_wp
    do k = 1, nf
      dmax = max(dmax, a(idx(k), idx(k)))
    end do
    tau = 0.0_wp
    do try = 0, SHIFT_TRIES
      call gather_block(a, idx, tau, work%h)
      call dpotrf_tiles('L', nf, work%h, size(work%h, 1), info)
      flops = flops + real(nf, wp)**3/3.0_wp
      if (info == 0) exit
      tau = merge(1.0e-14_wp*dmax, 100.0_wp*tau, try == 0)
    end do
    definite = info == 0
    if (.not. definite) return
    work%factored = work%factored + 1
    work%fac_nf = nf
    work%fac_free(1:nf) = idx
    work%fac_pos(idx) = [(k, k=1, nf)]
    work%fac_tau = tau
    work%fac_updates = 0
  end subroutine newton_factor

  !> No factor kept.
  subroutine newton_forget(work)
    type(newton_work_t), intent(inout) :: work
    if (work%fac_nf > 0) work%fac_pos(work%fac_free(1:work%fac_nf)) = 0
    work%fac_nf = -1
  end subroutine newton_forget

  !> True when `work` holds the factor LAPACK made of A(idx, idx) (idx ascending), not updated.
  logical function newton_holds(work, idx) result(yes)
    type(newton_work_t), intent(in) :: work
    integer, intent(in) :: idx(:)
    yes = .false.
    if (work%fac_nf /= size(idx) .or. work%fac_updates /= 0) return
    if (size(idx) == 0) return
    yes = all(work%fac_free(1:size(idx)) == idx)
  end function newton_holds

  !> A new solve with `work`: its working set is taken again from the warm start; the
  !! factor stays when `same_a` (the caller's A is the one the factor was made of) and it
  !! was made, not updated: a solve's first factor is then the one LAPACK makes of its first
  !! free set, to the bit, whether it is kept or made again (a run resumed from a checkpoint,
  !! which keeps no factor, takes the same steps); within the solve it is updated.
  subroutine newton_begin(work, same_a)
    type(newton_work_t), intent(inout) :: work
    logical, intent(in) :: same_a
    work%started = .false.
    work%at_min = .false.
    work%same_face = .false.
    work%shifts = 0
    if (same_a .and. work%fac_updates == 0) return
    call newton_forget(work)
  end subroutine newton_begin

  !> Delete row and column k of the Cholesky factor L (lower, p x p, in h): the rows below
  !! keep their first k - 1 columns, and the trailing block becomes the factor of
  !! L33 L33' + l l' (l = L(k+1:p, k)) by the rank-one update of plane rotations; the rows
  !! and columns after k move up and left by one.
  pure subroutine chol_delete(h, p, k)
    real(wp), intent(inout) :: h(:, :)
    integer, intent(in) :: p, k
    real(wp) :: v(p), r, c, s
    integer :: j
    v(k + 1:p) = h(k + 1:p, k)
    do j = k + 1, p
      r = hypot(h(j, j), v(j))
      c = r/h(j, j)
      s = v(j)/h(j, j)
      h(j, j) = r
      if (j < p) then
        h(j + 1:p, j) = (h(j + 1:p, j) + s*v(j + 1:p))/c
        v(j + 1:p) = c*v(j + 1:p) - s*h(j + 1:p, j)
      end if
    end do
    do j = 1, k - 1
      h(k:p - 1, j) = h(k + 1:p, j)
    end do
    do j = k + 1, p
      h(j - 1:p - 1, j - 1) = h(j:p, j)
    end do
  end subroutine chol_delete

  !> Append variable q to the factor L of A(idx, idx) (lower, p = size(idx), in h): its row
  !! w solves L w = A(idx, q), its pivot is A(q, q) - w'w (returned; its square root taken
  !! when positive).
  subroutine chol_append(a, idx, q, h, piv)
    real(wp), intent(in) :: a(:, :)
    integer, intent(in) :: idx(:), q
    real(wp), intent(inout) :: h(:, :)
    real(wp), intent(out) :: piv
    real(wp) :: w(size(idx))
    integer :: p
    p = size(idx)
    w = a(idx, q)
    if (p > 0) call dtrsv('L', 'N', 'N', p, h, size(h, 1), w, 1)
    piv = a(q, q) - dot_product(w, w)
    if (.not. piv > 0.0_wp) return
    h(p + 1, 1:p) = w
    h(p + 1, p + 1) = sqrt(piv)
  end subroutine chol_append

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
    if (allocated(work%fac_free)) deallocate (work%fac_free, work%fac_pos)
    allocate (work%fac_free(n))
    allocate (work%fac_pos(n), source=0)
    work%fac_nf = -1
    work%nfree = 0
    work%shifts = 0
    work%started = .false.
    work%at_min = .false.
  end subroutine ensure_work

end module qp_newton
