!> Two-body contact on the condensed interface (METHOD.md):
!! `solve_robin`: the Robin domain-decomposition iteration (each body's contact
!! problem against an obstacle by MPRGP, obstacles relaxed until the bodies agree);
!! `solve_monolithic`: the same discrete problem in one piece, the reference.
!! Everything here is interface-sized: O(m^2) per Hessian product.
module contact
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use config, only: deck_t
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_opts_t, mprgp_stats_t, mprgp_solve, lambda_max_estimate, &
                   MPRGP_CONVERGED, MPRGP_MAX_IT, mprgp_status_name
  use condense, only: interface_t, body_condensed_t
  implicit none
  private

  !> Outcome of a contact solve, with the outer history.
  type, public :: contact_result_t
    character(len=16) :: status = 'none'       !< converged | max_outer | diverged | failed | interrupted
    character(len=16) :: method = ''           !< robin | monolithic
    character(len=256) :: message = ''         !< why it failed, if it did
    integer :: outer = 0                       !< outer iterations (1 for monolithic)
    integer :: inner = 0                       !< Hessian multiplications, all subproblems (IT_inner)
    integer :: inner_maxit_hits = 0            !< subproblems that stopped on inner_max_it
    real(wp), allocatable :: lam(:)            !< (m) normal contact force, mean of the bodies' [force]
    real(wp), allocatable :: lam_body(:, :)    !< (m,2) each body's contact force [force]
    real(wp), allocatable :: w(:, :)           !< (m,2) B_a u_a, normal interface displacement [length]
    real(wp), allocatable :: gap(:)            !< (m) B_1u_1 + B_2u_2 - g0 [length]
    real(wp), allocatable :: obstacle(:, :)    !< (m,2) final obstacles G_a [length]
    real(wp) :: criterion = 0.0_wp             !< last value of the stopping criterion
    real(wp) :: residual = 0.0_wp              !< max(imbalance, penetration, complementarity)
    real(wp) :: imbalance = 0.0_wp             !< |lam_1 - lam_2| / |lam|
    real(wp) :: penetration = 0.0_wp           !< max(gap, 0) / displacement scale
    real(wp) :: complementarity = 0.0_wp       !< max lam_i |gap_i| / (max lam * displacement scale)
    integer :: active = 0                      !< nodes with lam > 0
    integer :: nhist = 0                       !< entries in the history
    real(wp), allocatable :: h_criterion(:)    !< per outer iteration
    real(wp), allocatable :: h_residual(:)     !< per outer iteration
    real(wp), allocatable :: h_wall(:)         !< wall time since the start of the iteration [s]
    integer, allocatable :: h_inner(:)         !< cumulative inner multiplications
    integer, allocatable :: h_active(:)        !< active contact nodes
  end type contact_result_t

  public :: solve_robin, solve_monolithic, interface_residual

contains

  !> The monolithic reference: min 1/2 lam'(F1+F2)lam - lam'(b1+b2-g0), lam >= 0.
  subroutine solve_monolithic(d, itf, bc, res)
    type(deck_t), intent(in) :: d                      !< deck (solver settings)
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies
    type(contact_result_t), intent(out) :: res         !< solution and status
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    real(wp), allocatable :: c(:), lb(:), g(:), lam(:)
    integer :: m, a
    real(wp) :: t0

    m = itf%m
    t0 = wtime()
    res%method = 'monolithic'
    call alloc_result(res, m, 1)
    allocate (c(m), lb(m), g(m), lam(m))
    call dense_op_init(op, bc(1)%flex + bc(2)%flex)
    c = bc(1)%b + bc(2)%b - itf%g0
    lb = 0.0_wp
    lam = 0.0_wp
    opts%rtol = d%solver%monolithic_rtol
    opts%max_it = d%solver%inner_max_it
    if (m > 0) then
      call mprgp_solve(op, c, lb, lam, opts, st, g)
      res%inner = st%n_matvec
      if (st%status /= MPRGP_CONVERGED) then
        res%status = merge('max_outer', 'failed   ', st%status == MPRGP_MAX_IT)
        res%message = 'monolithic MPRGP: '//trim(mprgp_status_name(st%status))//': '//trim(st%message)
      else
        res%status = 'converged'
      end if
    else
      res%status = 'converged'
    end if
    res%outer = 1
    res%lam = lam
    do a = 1, 2
      res%lam_body(:, a) = lam
      res%w(:, a) = bc(a)%b - matmul_sym(bc(a)%flex, lam)
      res%obstacle(:, a) = 0.0_wp
    end do
    call interface_residual(itf, bc, res)
    res%criterion = res%residual
    res%nhist = 1
    res%h_criterion(1) = res%criterion
    res%h_residual(1) = res%residual
    res%h_inner(1) = res%inner
    res%h_active(1) = res%active
    res%h_wall(1) = wtime() - t0
    if (res%status == 'converged' .and. .not. all_finite(lam)) then
      res%status = 'failed'
      res%message = 'monolithic solution has non-finite values'
    end if
  end subroutine solve_monolithic

  !> The Robin iteration of METHOD.md with relaxation delta, Steklov-Poincare or
  !! constant Robin operator, stopping on the increment or the residual.
  subroutine solve_robin(d, itf, bc, res, progress_unit)
    type(deck_t), intent(in) :: d                      !< deck (solver settings)
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies
    type(contact_result_t), intent(out) :: res         !< solution, status and history
    integer, intent(in), optional :: progress_unit     !< unit for progress lines (none if absent)
    type(dense_op_t) :: op(2)
    type(mprgp_opts_t) :: opts(2)
    type(mprgp_stats_t) :: st(2)
    real(wp), allocatable :: G(:, :), Gnew(:, :), lam(:, :), grad(:, :), rhs(:, :), lb(:)
    real(wp), allocatable :: dlam(:), corr(:, :), w(:, :)
    real(wp) :: delta, crit, best, rtol_in, t0, denom(2), ref, lmax(2), incr, progress, uref
    integer :: m, a, it, every, nmv(2), maxout, nthr
    logical :: steklov, done, printed

    m = itf%m
    t0 = wtime()
    nthr = body_threads()
    res%method = 'robin'
    maxout = d%solver%max_outer
    call alloc_result(res, m, maxout)
    allocate (G(m, 2), Gnew(m, 2), lam(m, 2), grad(m, 2), rhs(m, 2), lb(m), dlam(m), corr(m, 2), w(m, 2))
    delta = d%solver%delta
    steklov = d%solver%robin_operator /= 'constant'
    lb = 0.0_wp
    lam = 0.0_wp
    do a = 1, 2
      G(:, a) = itf%g0
    end do
    ref = tiny(1.0_wp) + 1.0e-14_wp*(maxabs(bc(1)%b) + maxabs(bc(2)%b) + maxabs(itf%g0))
    uref = max(maxabs(bc(1)%b), maxabs(bc(2)%b), maxabs(itf%g0), tiny(1.0_wp))

    ! Hessians and their largest eigenvalues, once per body (counted in IT_inner).
    nmv = 0
    lmax = 0.0_wp
    !$omp parallel do num_threads(nthr) schedule(static, 1) if (m > 64)
    do a = 1, 2
      call dense_op_init(op(a), bc(a)%flex)
      if (m > 0) lmax(a) = lambda_max_estimate(op(a), 30, nmv(a))
    end do
    !$omp end parallel do
    res%inner = sum(nmv)
    every = max(1, maxout/max(1, d%output%progress_lines))
    best = huge(1.0_wp)
    crit = huge(1.0_wp)
    progress = huge(1.0_wp)
    done = .false.
    res%status = 'max_outer'
    if (present(progress_unit)) write (progress_unit, '(a)') &
      '  outer   criterion    residual  active       inner'

    do it = 1, maxout
      if (it == 1) then
        rtol_in = d%solver%inner_rtol_max
      else
        rtol_in = min(d%solver%inner_rtol_max, max(d%solver%inner_rtol_min, d%solver%inner_factor*progress))
      end if
      ! 1. each body against its obstacle, in parallel
      !$omp parallel do num_threads(nthr) schedule(static, 1) if (m > 64)
      do a = 1, 2
        rhs(:, a) = bc(a)%b - G(:, a)
        opts(a)%rtol = rtol_in
        opts(a)%max_it = d%solver%inner_max_it
        opts(a)%lambda_max = lmax(a)
        if (m > 0) call mprgp_solve(op(a), rhs(:, a), lb, lam(:, a), opts(a), st(a), grad(:, a))
      end do
      !$omp end parallel do
      if (m == 0) then
        res%status = 'converged'; res%outer = it; done = .true.
        exit
      end if
      do a = 1, 2
        res%inner = res%inner + st(a)%n_matvec
        if (st(a)%status == MPRGP_MAX_IT) then
          res%inner_maxit_hits = res%inner_maxit_hits + 1
        else if (st(a)%status /= MPRGP_CONVERGED) then
          res%status = 'failed'
          write (res%message, '(a,i0,a,i0,a)') 'MPRGP failed on body ', a, ' at outer iteration ', it, &
            ': '//trim(mprgp_status_name(st(a)%status))//': '//trim(st(a)%message)
          exit
        end if
        ! B_a u_a = b_a - F_a lam_a = G_a - grad_a
        w(:, a) = G(:, a) - grad(:, a)
      end do
      if (res%status == 'failed') then
        res%outer = it
        exit
      end if
      ! 2. force imbalance and its Steklov-Poincare (or constant Robin) correction
      dlam = lam(:, 1) - lam(:, 2)
      if (steklov) then
        call op(2)%apply(dlam, corr(:, 1))   ! F_2 d, for body 1's obstacle
        call op(1)%apply(dlam, corr(:, 2))   ! F_1 d, for body 2's obstacle
        res%inner = res%inner + 2
      else
        corr(:, 1) = d%solver%alpha*dlam/itf%trib
        corr(:, 2) = corr(:, 1)
      end if
      ! 3. relaxed update of the obstacles
      Gnew(:, 1) = (1.0_wp - delta)*G(:, 1) + delta*(itf%g0 - w(:, 2) + corr(:, 1))
      Gnew(:, 2) = (1.0_wp - delta)*G(:, 2) + delta*(itf%g0 - w(:, 1) - corr(:, 2))

      ! a non-finite iterate is not kept: the result holds the last finite one
      if (.not. (all_finite(Gnew) .and. all_finite(lam) .and. all_finite(w))) then
        res%status = 'diverged'
        write (res%message, '(a,i0)') 'non-finite values in the outer iteration at iteration ', it
        exit
      end if
      ! true residual of the current iterate
      res%lam_body = lam
      res%lam = 0.5_wp*(lam(:, 1) + lam(:, 2))
      res%w = w
      call interface_residual(itf, bc, res)
      ! increment of the obstacles (the paper's criterion) and the stopping criterion
      do a = 1, 2
        denom(a) = max(norm2(Gnew(:, a)), ref)
      end do
      incr = norm2(Gnew(:, 1) - G(:, 1))/denom(1) + norm2(Gnew(:, 2) - G(:, 2))/denom(2)
      if (d%solver%stop == 'residual') then
        crit = res%residual
      else
        crit = incr
      end if
      ! the inner tolerance follows the outer progress: both the increment and the
      ! residual must shrink before the subproblems are solved tightly (a tolerance
      ! tied to the residual alone can freeze the obstacles and stall the iteration)
      progress = min(incr, res%residual)
      G = Gnew
      res%obstacle = G
      res%outer = it
      res%criterion = crit
      res%nhist = it
      res%h_criterion(it) = crit
      res%h_residual(it) = res%residual
      res%h_inner(it) = res%inner
      res%h_active(it) = res%active
      res%h_wall(it) = wtime() - t0
      printed = .false.
      if (present(progress_unit) .and. (it <= 5 .or. mod(it, every) == 0)) then
        write (progress_unit, '(i7,2es12.3,i8,i12)') it, crit, res%residual, res%active, res%inner
        printed = .true.
      end if
      if (.not. ieee_is_finite(crit)) then
        res%status = 'diverged'
        write (res%message, '(a,i0)') 'non-finite criterion at iteration ', it
        exit
      end if
      best = min(best, crit)
      if (it > 10 .and. crit > 1.0e4_wp*best .and. crit > 1.0_wp) then
        res%status = 'diverged'
        write (res%message, '(a,es10.3,a,es10.3)') 'criterion grew to ', crit, ' from its best ', best
        exit
      end if
      ! a relative increment stays bounded while the iterates blow up geometrically:
      ! watch the size of the obstacles against the displacements the loads cause
      if (maxval(abs(G)) > 1.0e6_wp*uref) then
        res%status = 'diverged'
        write (res%message, '(a,es10.3,a,es10.3,a)') 'obstacles grew to ', maxval(abs(G)), &
          ' (1e6 times the load displacement scale ', uref, ')'
        exit
      end if
      if (crit <= d%solver%tol) then
        res%status = 'converged'
        done = .true.
        exit
      end if
    end do
    if (present(progress_unit) .and. res%outer > 0) then
      if (.not. printed) write (progress_unit, '(i7,2es12.3,i8,i12)') res%outer, res%criterion, &
        res%residual, res%active, res%inner
    end if
    if (res%status == 'max_outer') write (res%message, '(a,i0,a,es10.3)') 'max_outer = ', maxout, &
      ' reached; last criterion ', res%criterion
  end subroutine solve_robin

  !> Gap, imbalance, penetration and complementarity of res%lam_body, res%w.
  subroutine interface_residual(itf, bc, res)
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies (scales)
    type(contact_result_t), intent(inout) :: res       !< lam_body, w in; residuals out
    real(wp) :: uscale, lnorm, lmax
    integer :: i
    if (itf%m == 0) then
      res%residual = 0.0_wp
      return
    end if
    res%lam = 0.5_wp*(res%lam_body(:, 1) + res%lam_body(:, 2))
    res%gap = res%w(:, 1) + res%w(:, 2) - itf%g0
    uscale = max(maxabs(bc(1)%b), maxabs(bc(2)%b), maxabs(itf%g0), maxabs(res%w(:, 1)), &
                 maxabs(res%w(:, 2)), tiny(1.0_wp))
    lnorm = norm2(res%lam)
    lmax = maxval(res%lam)
    if (lnorm > 0.0_wp) then
      res%imbalance = norm2(res%lam_body(:, 1) - res%lam_body(:, 2))/lnorm
    else
      res%imbalance = 0.0_wp
    end if
    res%penetration = max(maxval(res%gap), 0.0_wp)/uscale
    res%complementarity = 0.0_wp
    if (lmax > 0.0_wp) then
      do i = 1, itf%m
        res%complementarity = max(res%complementarity, max(res%lam(i), 0.0_wp)*abs(res%gap(i)))
      end do
      res%complementarity = res%complementarity/(lmax*uscale)
    end if
    res%residual = max(res%imbalance, res%penetration, res%complementarity)
    res%active = count(res%lam > 0.0_wp)
  end subroutine interface_residual

  subroutine alloc_result(res, m, nh)
    type(contact_result_t), intent(inout) :: res
    integer, intent(in) :: m, nh
    allocate (res%lam(m), res%lam_body(m, 2), res%w(m, 2), res%gap(m), res%obstacle(m, 2))
    allocate (res%h_criterion(nh), res%h_residual(nh), res%h_wall(nh), res%h_inner(nh), res%h_active(nh))
    res%lam = 0.0_wp; res%lam_body = 0.0_wp; res%w = 0.0_wp; res%gap = 0.0_wp; res%obstacle = 0.0_wp
    res%h_criterion = 0.0_wp; res%h_residual = 0.0_wp; res%h_wall = 0.0_wp; res%h_inner = 0; res%h_active = 0
  end subroutine alloc_result

  function matmul_sym(a, x) result(y)
    real(wp), intent(in) :: a(:, :), x(:)
    real(wp) :: y(size(x))
    y = matmul(a, x)
  end function matmul_sym

  real(wp) function maxabs(x)
    real(wp), intent(in) :: x(:)
    maxabs = 0.0_wp
    if (size(x) > 0) maxabs = maxval(abs(x))
  end function maxabs

  logical function all_finite(x)
    real(wp), intent(in) :: x(..)
    select rank (x)
    rank (1)
      all_finite = all(ieee_is_finite(x))
    rank (2)
      all_finite = all(ieee_is_finite(x))
    rank default
      all_finite = .false.
    end select
  end function all_finite

  real(wp) function wtime()
    use omp_lib, only: omp_get_wtime
    wtime = omp_get_wtime()
  end function wtime

  !> Threads for the two bodies: min(2, OMP max threads).
  integer function body_threads()
    use omp_lib, only: omp_get_max_threads
    body_threads = max(1, min(2, omp_get_max_threads()))
  end function body_threads

end module contact
