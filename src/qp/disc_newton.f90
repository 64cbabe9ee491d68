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
!! The face's matrix is solved through a Cholesky factor of A on the free variables and the
!! held discs' pairs (disc_factor_t), made once a solve (`dpotrf_tiles`) and then carried
!! from face to face by row updates (a disc that reaches its circle costs O(p^2), not a
!! new O(p^3) factor), with the Schur complement on the held discs' tangents, which turn
!! at every step. A caller that solves nearby problems with the same A (the Robin
!! iteration's solves of a body) may carry the factor from one solve to the next: a solve
!! takes it only when it is what a new factorization of its first face makes, bit for bit
!! (disc_factor_t%carried). Blockers within a negligible part of a step (TINY_STEP: on
!! their bounds but for rounding) are held all at once. Each step computes the gradient
!! afresh (one product with A; the projection makes a recurrence inexact).
!!
!! Thread safety: no module variables; the work arrays are the caller's.
module disc_newton
  use kinds, only: wp
  use lapack, only: dpotrf_tiles, dpotrf, dpotrs, dsymv, dtrsv, dgemv, dsyrk
  use tangent_discs, only: disc_set_t, circle_point
  use qp_newton, only: chol_delete, chol_append
  implicit none (type, external)
  private

  public :: disc_newton_step, disc_held, disc_factor_t, face_solve
  public :: DN_STEP, DN_STILL, DN_NOT_SPD

  integer, parameter :: DN_STEP = 0       !< a step was taken
  integer, parameter :: DN_STILL = 1      !< no step: x is its face's minimiser and nothing is released
  integer, parameter :: DN_NOT_SPD = 2    !< the face's matrix is not positive definite (A is not SPD)
  integer, parameter :: MAX_HALVING = 40
  !> a step cut at most this part of its length is a blocker on its bound but for rounding
  real(wp), parameter :: TINY_STEP = 1.0e-6_wp

  !> The factor the steps of one solve carry: L L' = A(U, U), U the free variables (the
  !! F part, first) then both variables of each held disc (the P part, in pairs, last).
  !! A step whose face is a few variables away updates it (rows deleted, inserted at the
  !! end of the F part, discs appended) instead of factoring the face again; the face's
  !! matrix Z'AZ + C is then solved through the Schur complement on the held discs'
  !! tangents (face_solve), O(p nd^2) where a new factor costs O(p^3).
  type :: disc_factor_t
    real(wp), allocatable :: h(:, :)     !< (n, n) the factor in its leading p x p block
    integer, allocatable :: var(:)       !< (n) the variable at each position
    integer, allocatable :: pos(:)       !< (n) the position of each variable (0: none)
    integer, allocatable :: pdisc(:)     !< the disc at each pair of the P part
    integer :: nf = 0                    !< the F part's length
    integer :: nd = 0                    !< the P part's discs
    integer :: updates = 0               !< rows changed since the factor was made
    logical :: valid = .false.           !< h holds a factor
    !> the factor comes from an earlier solve with the same A (set at a solve's start): its
    !! first step takes it only when it is a new factor (no updates since it was made) of
    !! exactly that step's face, and then it is bit for bit what factoring the face makes
    !! (the order of a new factor is the face's; fresh); otherwise it is made anew. So the
    !! solve does what it would do without it, on a resumed run as on the uninterrupted one
    logical :: carried = .false.
  end type disc_factor_t

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
  subroutine disc_newton_step(a, b, set, x, g, ax, held, at_min, outcome, flops, factored, fac)
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
    type(disc_factor_t), intent(inout) :: fac !< the factor of the solve's last face (carried)
    integer, allocatable :: free(:), dk(:)
    real(wp), allocatable :: rhs(:), tau(:, :), curv(:), d(:), dfree(:), x0(:), g0(:), xb(:), axb(:)
    logical, allocatable :: rel(:), onb(:)
    integer :: n, nf, nd, k, i, blk, half, q
    real(wp) :: t, tmax, df, noise, s, na, nb
    logical :: cut, definite
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
    allocate (rhs(nf + nd))
    call face_solve(a, set, free, dk, tau, curv, g, fac, rhs, definite, flops, factored)
    if (.not. definite) then
      outcome = DN_NOT_SPD
      return
    end if
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
    ! blockers within a negligible part of the step (variables on a bound but for rounding: a
    ! warm start's leftovers) are all held at once and pinned there, and the next step is the
    ! Newton step of that face; not a step of length ~0 for each of them
    if (blk /= 0 .and. tmax <= TINY_STEP) then
      do while (blk /= 0 .and. tmax <= TINY_STEP)
        call set%pin(x, dfree, blk)
        if (set%disc(blk) > 0) then
          held(set%pair(:, set%disc(blk))) = .true.
          dfree(set%pair(:, set%disc(blk))) = 0.0_wp
        else
          held(blk) = .true.
          dfree(blk) = 0.0_wp
        end if
        call set%max_step(x, dfree, 1.0_wp, tmax, blk)
        tmax = max(tmax, 0.0_wp)
      end do
      call dsymv('U', n, 1.0_wp, a, n, x, 1, 0.0_wp, ax, 1)
      g = ax - b
      flops = flops + 2.0_wp*real(n, wp)**2
      at_min = .false.
      return
    end if
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

  !> The Newton direction on the face (module header): rhs = delta (the free variables in
  !! the order of `free`, then the held discs' tangential coordinates in the order of dk)
  !! from (Z'AZ + C) delta = -Z'g. With L = [Lf 0; W' Lp] the factor of A(U, U) (F part
  !! then P part, bring_to_face) and T the held discs' tangents (2 nd x nd), Z'AZ + C =
  !! [Lf 0; T'W' K] [Lf' WT; 0 K'] where K K' = S = T'Lp Lp'T + C (nd x nd). definite
  !! false (rhs undefined): the face's matrix is not positive definite, an outcome of the
  !! step (DN_NOT_SPD), not a failure.
  subroutine face_solve(a, set, free, dk, tau, curv, g, fac, rhs, definite, flops, factored)
    real(wp), intent(in) :: a(:, :)
    type(disc_set_t), intent(in) :: set
    integer, intent(in) :: free(:), dk(:)
    real(wp), intent(in) :: tau(:, :), curv(:), g(:)
    type(disc_factor_t), intent(inout) :: fac
    real(wp), intent(out) :: rhs(:)
    logical, intent(out) :: definite
    real(wp), intent(inout) :: flops
    integer, intent(inout) :: factored
    real(wp), allocatable :: gt(:, :), sm(:, :), zf(:), v(:), tq(:, :)
    integer, allocatable :: dq(:)
    integer :: nf, nd, np, ld, i, q, k, j, info
    definite = .false.
    nf = size(free)
    nd = size(dk)
    call bring_to_face(a, set, free, dk, fac, info, flops, factored)
    if (info /= 0) return
    np = 2*nd
    ld = size(fac%h, 1)
    ! the tangents in the P part's order
    allocate (tq(2, nd), dq(nd))
    do i = 1, nd
      dq(i) = (fac%pos(set%pair(1, dk(i))) - nf + 1)/2
      tq(:, dq(i)) = tau(:, i)
    end do
    ! z_F = Lf^-1 r_F, r_F = -g_F (F part's order)
    allocate (zf(nf), v(np))
    do i = 1, nf
      zf(i) = -g(fac%var(i))
    end do
    if (nf > 0) call dtrsv('L', 'N', 'N', nf, fac%h, ld, zf, 1)
    flops = flops + real(nf, wp)**2
    if (nd > 0) then
      ! G = Lp' T (np x nd), S = G'G + C
      allocate (gt(np, nd), sm(nd, nd))
      do q = 1, nd
        do i = 1, np
          j = nf + i
          gt(i, q) = 0.0_wp
          if (i <= 2*q - 1) gt(i, q) = fac%h(nf + 2*q - 1, j)*tq(1, q)
          if (i <= 2*q) gt(i, q) = gt(i, q) + fac%h(nf + 2*q, j)*tq(2, q)
        end do
      end do
      call dsyrk('L', 'T', nd, np, 1.0_wp, gt, np, 0.0_wp, sm, nd)
      do i = 1, nd
        sm(dq(i), dq(i)) = sm(dq(i), dq(i)) + curv(i)
      end do
      call dpotrf('L', nd, sm, nd, info)
      flops = flops + real(np, wp)*real(nd, wp)**2 + real(nd, wp)**3/3.0_wp + 4.0_wp*real(np, wp)*nd
      if (info /= 0) return
      ! y = r_D - T'W'z_F, delta_D = S^-1 y
      v = 0.0_wp
      if (nf > 0) call dgemv('N', np, nf, 1.0_wp, fac%h(nf + 1, 1), ld, zf, 1, 0.0_wp, v, 1)
      do q = 1, nd
        k = fac%pdisc(q)
        rhs(nf + q) = -(tq(1, q)*g(set%pair(1, k)) + tq(2, q)*g(set%pair(2, k))) - &
                      (tq(1, q)*v(2*q - 1) + tq(2, q)*v(2*q))
      end do
      call dpotrs('L', nd, 1, sm, nd, rhs(nf + 1:), nd, info)
      if (info /= 0) return
      ! z_F - W T delta_D
      do q = 1, nd
        v(2*q - 1:2*q) = tq(:, q)*rhs(nf + q)
      end do
      if (nf > 0) call dgemv('T', np, nf, -1.0_wp, fac%h(nf + 1, 1), ld, v, 1, 1.0_wp, zf, 1)
      flops = flops + 4.0_wp*real(np, wp)*nf + 2.0_wp*real(nd, wp)**2
    end if
    if (nf > 0) call dtrsv('L', 'T', 'N', nf, fac%h, ld, zf, 1)
    flops = flops + real(nf, wp)**2
    ! back to the caller's orders: F in the order of `free`, the discs in that of dk
    do i = 1, nf
      rhs(i) = zf(fac%pos(free(i)))
    end do
    if (nd > 0) then
      v(1:nd) = rhs(nf + 1:nf + nd)
      do i = 1, nd
        rhs(nf + i) = v(dq(i))
      end do
    end if
    definite = .true.
  end subroutine face_solve

  !> fac brought to the face (free, dk): a new factor when it holds none or the face is
  !! far from its own (over p/12 rows to change at once, or p/2 since it was made, or an
  !! update that loses positive definiteness); else the rows that left it deleted (the
  !! last first), the variables that joined F inserted at the end of the F part, the
  !! discs newly held appended as pairs. info /= 0: A(U, U) is not positive definite.
  subroutine bring_to_face(a, set, free, dk, fac, info, flops, factored)
    real(wp), intent(in) :: a(:, :)
    type(disc_set_t), intent(in) :: set
    integer, intent(in) :: free(:), dk(:)
    type(disc_factor_t), intent(inout) :: fac
    integer, intent(out) :: info
    real(wp), intent(inout) :: flops
    integer, intent(inout) :: factored
    logical, allocatable :: in_f(:), in_d(:), keep(:)
    integer :: n, p, np, pc, nchange, i, k, q, v
    real(wp) :: piv
    logical :: was_carried
    n = size(a, 1)
    info = 0
    ! a factor of a problem of another size holds nothing of this one
    if (allocated(fac%h)) then
      if (size(fac%h, 1) /= max(1, n) .or. size(fac%pos) /= n) then
        deallocate (fac%h, fac%var, fac%pos, fac%pdisc)
        fac%valid = .false.
      end if
    end if
    if (.not. allocated(fac%h)) then
      allocate (fac%h(max(1, n), max(1, n)), fac%var(n), fac%pdisc(0))
      allocate (fac%pos(n), source=0)
      fac%valid = .false.
    end if
    was_carried = fac%carried
    fac%carried = .false.
    allocate (in_f(n), in_d(size(set%r)), source=.false.)
    in_f(free) = .true.
    in_d(dk) = .true.
    if (fac%valid) then
      p = fac%nf + 2*fac%nd
      allocate (keep(p))
      do i = 1, fac%nf
        keep(i) = in_f(fac%var(i))
      end do
      do q = 1, fac%nd
        keep(fac%nf + 2*q - 1:fac%nf + 2*q) = in_d(fac%pdisc(q))
      end do
      nchange = count(.not. keep) + count(fac%pos(free) == 0 .or. fac%pos(free) > fac%nf)
      do i = 1, size(dk)
        if (fac%pos(set%pair(1, dk(i))) <= fac%nf) nchange = nchange + 2
      end do
      if (nchange == 0 .and. .not. (was_carried .and. fac%updates > 0)) then
        ! a carried factor taken is counted as made: the work reported does not depend on
        ! it (a resumed run, which makes it, reports the same)
        if (was_carried) flops = flops + real(p, wp)**3/3.0_wp
        return
      end if
      if (.not. was_carried .and. 12*nchange <= p .and. 2*(fac%updates + nchange) <= p) then
        call update()
        if (info == 0) return
      end if
    end if
    call fresh()
  contains

    subroutine update()
      integer :: j
      ! deletions, the last position first (the positions above stay valid)
      pc = p
      do j = p, 1, -1
        if (keep(j)) cycle
        call chol_delete(fac%h, pc, j)
        flops = flops + 4.0_wp*real(pc - j, wp)**2
        fac%pos(fac%var(j)) = 0
        fac%var(j:pc - 1) = fac%var(j + 1:pc)
        pc = pc - 1
        if (j <= fac%nf) then
          fac%nf = fac%nf - 1
        else if (mod(j - fac%nf, 2) == 1) then
          ! the pair's first variable: the disc leaves (its second went first)
          q = (j - fac%nf + 1)/2
          fac%pdisc(q:fac%nd - 1) = fac%pdisc(q + 1:fac%nd)
          fac%nd = fac%nd - 1
        end if
      end do
      np = 2*fac%nd
      call renumber()
      ! the variables that joined F, at the end of the F part
      do i = 1, size(free)
        v = free(i)
        if (fac%pos(v) > 0) cycle
        call chol_insert(a, fac, v, piv, flops)
        if (.not. piv > 1.0e-8_wp*a(v, v)) then
          info = 1
          return
        end if
      end do
      ! the discs newly held, as pairs at the end
      do i = 1, size(dk)
        k = dk(i)
        if (fac%pos(set%pair(1, k)) > 0) cycle
        do j = 1, 2
          v = set%pair(j, k)
          p = fac%nf + 2*fac%nd + j - 1
          call chol_append(a, fac%var(1:p), v, fac%h, piv)
          flops = flops + real(p, wp)**2
          if (.not. piv > 1.0e-8_wp*a(v, v)) then
            info = 1
            return
          end if
          fac%var(p + 1) = v
          fac%pos(v) = p + 1
        end do
        fac%pdisc = [fac%pdisc(1:fac%nd), k]
        fac%nd = fac%nd + 1
      end do
      fac%updates = fac%updates + nchange
    end subroutine update

    !> A new factor: F in the order of `free`, then the discs of dk.
    subroutine fresh()
      integer :: i2, j2, pp
      real(wp), allocatable :: t(:, :)
      call forget()
      fac%nf = size(free)
      fac%nd = size(dk)
      pp = fac%nf + 2*fac%nd
      fac%var(1:fac%nf) = free
      do i2 = 1, fac%nd
        fac%var(fac%nf + 2*i2 - 1:fac%nf + 2*i2) = set%pair(:, dk(i2))
      end do
      fac%pdisc = dk
      ! in a pp x pp array of its own: the factor's bits depend on A on the face alone, not
      ! on the size of the problem (h's leading dimension)
      allocate (t(pp, pp))
      do j2 = 1, pp
        do i2 = j2, pp
          t(i2, j2) = a(fac%var(i2), fac%var(j2))
        end do
      end do
      call dpotrf_tiles('L', pp, t, pp, info)
      flops = flops + real(pp, wp)**3/3.0_wp
      factored = factored + 1
      if (info /= 0) return
      do j2 = 1, pp
        fac%h(j2:pp, j2) = t(j2:pp, j2)
      end do
      call renumber()
      fac%updates = 0
      fac%valid = .true.
    end subroutine fresh

    subroutine forget()
      fac%pos = 0
      fac%valid = .false.
      fac%nf = 0
      fac%nd = 0
    end subroutine forget

    subroutine renumber()
      integer :: j
      do j = 1, fac%nf + 2*fac%nd
        fac%pos(fac%var(j)) = j
      end do
    end subroutine renumber

  end subroutine bring_to_face

  !> Variable v inserted at the end of the F part (position nf + 1) of the factor
  !! [Lf 0; W' Lp]: its row l solves Lf l = A(F, v), its pivot d = sqrt(A(v,v) - l'l)
  !! (piv = d^2, nothing changed when not positive), its column below c = (A(P, v) - W'l)/d,
  !! and Lp becomes the factor of Lp Lp' - c c' (chol_downdate); the P part moves down a
  !! row. piv is set to 0 when the downdate fails (the face is then factored anew).
  subroutine chol_insert(a, fac, v, piv, flops)
    real(wp), intent(in) :: a(:, :)
    type(disc_factor_t), intent(inout) :: fac
    integer, intent(in) :: v
    real(wp), intent(out) :: piv
    real(wp), intent(inout) :: flops
    real(wp), allocatable :: l(:), c(:), w(:)
    integer :: nf, np, ld, j
    logical :: ok
    nf = fac%nf
    np = 2*fac%nd
    ld = size(fac%h, 1)
    allocate (l(nf), c(np))
    l = a(fac%var(1:nf), v)
    if (nf > 0) call dtrsv('L', 'N', 'N', nf, fac%h, ld, l, 1)
    piv = a(v, v) - dot_product(l, l)
    flops = flops + real(nf, wp)**2 + 2.0_wp*real(np, wp)*nf + 4.0_wp*real(np, wp)**2
    if (.not. piv > 0.0_wp) return
    if (np > 0) then
      c = a(fac%var(nf + 1:nf + np), v)
      if (nf > 0) call dgemv('N', np, nf, -1.0_wp, fac%h(nf + 1, 1), ld, l, 1, 1.0_wp, c, 1)
      c = c/sqrt(piv)
      w = c
      call chol_downdate(fac%h(nf + 1:nf + np, nf + 1:nf + np), w, ok)
      if (.not. ok) then
        piv = 0.0_wp
        return
      end if
      ! the P part down a row and a column
      do j = nf + np, nf + 1, -1
        fac%h(j + 2:nf + np + 1, j + 1) = fac%h(j + 1:nf + np, j)
        fac%h(j + 1, j + 1) = fac%h(j, j)
      end do
      do j = 1, nf
        fac%h(nf + 2:nf + np + 1, j) = fac%h(nf + 1:nf + np, j)
      end do
      fac%h(nf + 2:nf + np + 1, nf + 1) = c
    end if
    fac%h(nf + 1, 1:nf) = l
    fac%h(nf + 1, nf + 1) = sqrt(piv)
    fac%var(nf + 2:nf + np + 1) = fac%var(nf + 1:nf + np)
    fac%var(nf + 1) = v
    fac%nf = nf + 1
    do j = nf + 1, nf + np + 1
      fac%pos(fac%var(j)) = j
    end do
  end subroutine chol_insert

  !> L (lower, n x n) becomes the factor of L L' - c c' by hyperbolic plane rotations
  !! (c is overwritten); ok false (L then undefined) when that is not positive definite
  !! to working precision.
  pure subroutine chol_downdate(l, c, ok)
    real(wp), intent(inout) :: l(:, :)
    real(wp), intent(inout) :: c(:)
    logical, intent(out) :: ok
    integer :: j, n
    real(wp) :: r2, r, co, si
    n = size(c)
    ok = .false.
    do j = 1, n
      r2 = (l(j, j) - c(j))*(l(j, j) + c(j))
      if (.not. r2 > (64.0_wp*epsilon(1.0_wp)*l(j, j))**2) return
      r = sqrt(r2)
      co = r/l(j, j)
      si = c(j)/l(j, j)
      l(j, j) = r
      if (j < n) then
        l(j + 1:n, j) = (l(j + 1:n, j) - si*c(j + 1:n))/co
        c(j + 1:n) = co*c(j + 1:n) - si*l(j + 1:n, j)
      end if
    end do
    ok = .true.
  end subroutine chol_downdate

end module disc_newton
