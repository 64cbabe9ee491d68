!> The a posteriori bound of the error of a contact force against the monolithic solution
!! of the same discrete problem (doc/method.md, "Method as implemented", accuracy bound),
!! with the projection on the feasible set of floating bodies.
module error_estimate
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use lapack, only: dsymv, dpotrf_tiles, dtrsv, dposv, dsyev
  use contact_interface, only: interface_t, slot_row, row_bounds, disc_rows
  use constraint_set, only: constraint_set_t
  use tangent_discs, only: friction_set
  use condense, only: body_condensed_t
  use contact_common, only: scatter, body_threads
  use linop, only: csc_op_t
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_AMD
  use monolithic, only: assemble_hessian
  use errors, only: error_t
  use contact_types, only: contact_result_t
  use equality_rows, only: stacked_columns
  use nonneg_lsq, only: sparse_cols_t, gram_t, NNLS_DENSE_MAX
  implicit none (type, external)
  private

  !> H = sum_a E_a' F_a E_a for the bound: its products, its Cholesky factor and solves.
  type :: hessian_t
    integer :: m = 0
    logical :: sparse = .false.              !< several pairs: CSC and CHOLMOD
    real(wp), allocatable :: h(:, :), a(:, :)  !< dense H and its factor (one pair)
    type(csc_op_t) :: hc                     !< sparse H (several pairs)
    type(chol_t) :: chol                     !< its CHOLMOD factor
  contains
    procedure :: init => hessian_init
    procedure :: apply => hessian_apply
    procedure :: factor => hessian_factor
    procedure :: solve => hessian_solve
  end type hessian_t

  public :: error_bound

contains

  !> A posteriori bound of the error of res%lam against the monolithic solution lam* of
  !! the same discrete problem: for the strongly convex QP min 1/2 l'Hl - c'l, l >= 0
  !! (H = sum_a E_a' F_a E_a, c = sum_a E_a' b_a - g0) and the natural residual
  !! r = l - max(0, l - (Hl - c)/L), |l - lam*| <= 2 (L/rq) |r| with L, rq the extreme
  !! eigenvalues of H (estimated by power and inverse iteration, kappa enlarged by 10%).
  !! Sets res%error_bound (relative to |lam|) and res%kappa. H is dense for two bodies in one
  !! pair, sparse (CHOLMOD) for several pairs.
  subroutine error_bound(contact_line, bodies, res)
    type(interface_t), intent(in) :: contact_line        !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)      !< condensed bodies
    type(contact_result_t), intent(inout) :: res         !< lam in; error_bound, kappa out
    type(hessian_t) :: hs
    class(constraint_set_t), allocatable :: set
    real(wp), allocatable :: g(:), r(:), x(:), y(:), xp(:), yp(:), bs(:, :), lo(:), hi(:)
    real(wp) :: lmax, lmin, nl, perr, lprev, rq, mprev
    integer :: m, i, k, ki, ib
    logical :: definite
    type(error_t) :: serr     ! a solve with the factor of H
    m = contact_line%m
    res%error_bound = 0.0_wp
    res%kappa = 1.0_wp
    if (m == 0) return
    if (sum(bodies(:)%nrig) > 0 .and. size(disc_rows(contact_line), 2) > 0) then
      ! the projection on {discs, G l = e} is not available (project_feasible's dual Newton
      ! method clips to a box): no bound, and none of its eigenvalue estimates
      res%error_bound = huge(1.0_wp)
      res%kappa = huge(1.0_wp)
      res%no_bound_reason = 'no projection onto the friction discs together with the equilibrium of a body held '// &
                            'only by contact'
      return
    end if
    allocate (g(m), r(m), x(m), y(m), xp(m), yp(m), bs(m, 2))
    ! H = sum_a E_a' F_a E_a: dense for two bodies in one pair (F_1 + F_2), sparse otherwise
    call hs%init(contact_line, bodies)
    bs = 0.0_wp
    do ib = 1, size(bodies)
      call scatter(bodies(ib)%b, bodies(ib)%slots, bs)
    end do
    ! the largest eigenvalue (power iteration, a lower estimate, enlarged below) and the
    ! smallest (inverse iteration on the Cholesky factor of H) on two threads
    !$omp parallel sections num_threads(body_threads()) private(i, k, ki, lprev, mprev) if (m > 64)
    !$omp section
    do i = 1, m
      xp(i) = 1.0_wp + 0.5_wp*sin(real(i, wp))
    end do
    xp = xp/norm2(xp)
    lmax = 0.0_wp
    do k = 1, 60
      call hs%apply(xp, yp)
      lprev = lmax
      lmax = norm2(yp)
      if (.not. lmax > 0.0_wp) exit
      xp = yp/lmax
      ! settled: the estimate moves by less than 1e-6 an iteration (kappa is enlarged by 10%)
      if (k >= 5 .and. abs(lmax - lprev) <= 1.0e-6_wp*lmax) exit
    end do
    !$omp section
    call hs%factor(definite)
    if (definite) then
      do i = 1, m
        x(i) = 1.0_wp + 0.5_wp*cos(real(3*i, wp))
      end do
      x = x/norm2(x)
      rq = 0.0_wp
      do ki = 1, 60
        y = x
        call hs%solve(y, serr)
        if (serr%failed()) then     ! no estimate of lambda_min: no bound
          definite = .false.
          exit
        end if
        ! x'H^-1 x, an estimate of 1/lambda_min from below: settled when it moves by less
        ! than 1e-6 an iteration
        mprev = rq
        rq = dot_product(x, y)
        x = y/norm2(y)
        if (ki >= 5 .and. abs(rq - mprev) <= 1.0e-6_wp*abs(rq)) exit
      end do
    end if
    !$omp end parallel sections
    if (.not. definite .or. .not. lmax > 0.0_wp) then
      res%error_bound = huge(1.0_wp)
      res%kappa = huge(1.0_wp)
      return
    end if
    call hs%apply(x, y)
    lmin = dot_product(x, y)
    res%kappa = 1.1_wp*lmax/max(lmin, tiny(1.0_wp))
    if (.not. (ieee_is_finite(res%kappa) .and. ieee_is_finite(lmax) .and. lmax > 0.0_wp)) then
      ! out of the range of double precision: no bound can be given
      res%kappa = huge(1.0_wp)
      res%error_bound = huge(1.0_wp)
      return
    end if
    ! natural residual of the mean contact force
    call hs%apply(res%lam, g)
    g = g - (bs(:, 1) + bs(:, 2) - contact_line%g0)
    ! the feasible set: l >= 0 on the normal rows, with friction a box on the tangential
    ! ones (Coulomb: the box of the final normal forces, i.e. the bound is the one of the
    ! fixed point reached)
    allocate (lo(m), hi(m))
    call row_bounds(contact_line, res%lam, lo, hi)
    set = friction_set(lo, hi, disc_rows(contact_line))
    if (sum(bodies(:)%nrig) > 0) then
      ! floating bodies: the feasible set is {lo <= l <= hi, G l = e}, and the bound holds with the
      ! projection on it (the proof only uses the projection's variational inequality and
      ! the strong convexity of the objective on R^m); the projection's own inaccuracy is added
      call project_feasible(bodies, m, res%lam - g/lmax, lo, hi, y, perr)
      r = res%lam - y
    else
      ! the projection onto the box, or onto its discs in space
      y = res%lam - g/lmax
      call set%project(y)
      r = res%lam - y
      perr = 0.0_wp
    end if
    nl = norm2(res%lam)
    ! the residual itself is computed in floating point: add its rounding level
    if (.not. perr < 0.01_wp*huge(1.0_wp)) then
      ! the projection on the feasible set is not known to any accuracy: no bound
      res%error_bound = huge(1.0_wp)
    else if (nl > 0.0_wp) then
      res%natural = (norm2(r) + perr)/nl
      res%error_bound = 2.0_wp*res%kappa*((norm2(r) + perr)/nl + 10.0_wp*real(m, wp)*epsilon(1.0_wp))
    else
      res%error_bound = merge(0.0_wp, huge(1.0_wp), norm2(r) == 0.0_wp)
    end if
  end subroutine error_bound

  !> H: dense with LAPACK's Cholesky for one pair, sparse with CHOLMOD's for several.
  subroutine hessian_init(self, contact_line, bodies)
    class(hessian_t), intent(inout) :: self
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer :: m, i, j, ib
    integer, allocatable :: rows(:)
    real(wp) :: row_sums
    m = contact_line%m
    self%m = m
    self%sparse = contact_line%npair > 1
    if (self%sparse) then
      call assemble_hessian(contact_line, bodies, self%hc, row_sums, sorted=.true.)
      return
    end if
    allocate (self%h(m, m))
    self%h = 0.0_wp
    do ib = 1, size(bodies)
      rows = slot_row(bodies(ib)%slots, m)
      do j = 1, bodies(ib)%m
        do i = 1, bodies(ib)%m
          self%h(rows(i), rows(j)) = self%h(rows(i), rows(j)) + bodies(ib)%flex(i, j)
        end do
      end do
    end do
  end subroutine hessian_init

  !> y = H x.
  subroutine hessian_apply(self, x, y)
    class(hessian_t), intent(inout) :: self
    real(wp), intent(in) :: x(:)
    real(wp), intent(out) :: y(:)
    if (self%sparse) then
      call self%hc%apply(x, y)
    else
      call dsymv('U', self%m, 1.0_wp, self%h, self%m, x, 1, 0.0_wp, y, 1)
    end if
  end subroutine hessian_apply

  !> The Cholesky factor of H; definite false when H is not positive definite (then there
  !! is no inverse iteration and no bound).
  subroutine hessian_factor(self, definite)
    class(hessian_t), intent(inout) :: self
    logical, intent(out) :: definite
    integer :: info
    type(error_t) :: err
    if (self%sparse) then
      call self%chol%factor(self%m, self%hc%colptr, self%hc%rowind, self%hc%val, FACT_CHOLMOD, ORD_AMD, err)
      definite = .not. err%failed()
    else
      self%a = self%h
      call dpotrf_tiles('L', self%m, self%a, self%m, info)
      definite = info == 0
    end if
  end subroutine hessian_factor

  !> x <- H^-1 x (after hessian_factor). Dense: the two triangular solves with L and L'
  !! (dtrsv; dpotrs with one right-hand side goes through dtrsm, three times slower here).
  subroutine hessian_solve(self, x, err)
    class(hessian_t), intent(inout) :: self
    real(wp), intent(inout), contiguous :: x(:)
    type(error_t), intent(out) :: err     !< CHOLMOD's solve failed (then: no bound)
    if (self%sparse) then
      call self%chol%solve(x, err)
    else
      call dtrsv('L', 'N', 'N', self%m, self%a, self%m, x, 1)
      call dtrsv('L', 'T', 'N', self%m, self%a, self%m, x, 1)
    end if
  end subroutine hessian_solve

  !> z = the Euclidean projection of y on {lo <= l <= hi, G l = e} (G, e: the floating bodies'
  !! equilibrium rows, stacked): z = P(y - G'nu), P the clipping to [lo, hi], with nu the
  !! minimiser of the convex, piecewise quadratic phi(nu) = 1/2 |P(y - G'nu)|^2 + e'nu (r
  !! unknowns; lo = 0 makes |P(v)|^2 the usual form), by Newton steps on the current free set
  !! (Hessian G_P G_P', a small ridge when it is singular) with a backtracking line search
  !! on phi: exact once the positive set is right, whatever the conditioning of G on it.
  !! perr bounds |z - exact projection| by the equilibrium left, |G z - e| /
  !! sqrt(lambda_min(G_P G_P')). G_P G_P' is dense (LAPACK; lambda_min by dsyev) up to
  !! NNLS_DENSE_MAX rows, sparse beyond (a sparse Cholesky factor per Newton step; lambda_min
  !! by inverse iteration, less its residual: a lower bound once it has converged): a
  !! chain of floating bodies couples each body's rows to its neighbours' only.
  subroutine project_feasible(bodies, m_rows, y, lo, hi, z, perr)
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: m_rows                   !< contact rows of all pairs
    real(wp), intent(in) :: y(:)
    real(wp), intent(in) :: lo(:), hi(:)            !< the bounds of the forces (row_bounds)
    real(wp), allocatable, intent(out) :: z(:)
    real(wp), intent(out) :: perr
    type(sparse_cols_t) :: gs
    type(gram_t) :: gm
    type(error_t) :: err
    real(wp), allocatable :: es(:), nu(:), f(:), h(:, :), d(:), nt(:), ev(:), work(:), rn(:)
    real(wp) :: phi, phit, t, ridge, lmin
    integer :: m, r, it, k, info, l
    logical :: dense
    m = size(y)
    call stacked_columns(bodies, m_rows, gs, es)
    r = size(es)
    dense = r <= NNLS_DENSE_MAX
    allocate (nu(r), f(r), d(r), nt(r), rn(r))
    ! the ridge: 1e-14 of the largest row norm squared of G
    rn = 0.0_wp
    do l = 1, gs%ptr(m + 1) - 1
      rn(gs%row(l)) = rn(gs%row(l)) + gs%val(l)**2
    end do
    ridge = 1.0e-14_wp*maxval(rn)
    if (dense) then
      allocate (h(r, r))
    else
      call gm%build(gs, [(k, k=1, r + 1)])
    end if
    nu = 0.0_wp
    z = project(nu)
    phi = 0.5_wp*sum(z**2) + dot_product(es, nu)
    do it = 1, 200
      f = gs%times(z) - es             ! = -grad phi
      if (norm2(f) <= 1.0e-15_wp*max(norm2(es), tiny(1.0_wp))) exit
      d = f
      if (dense) then
        call gram(z, h)
        do k = 1, r
          h(k, k) = h(k, k) + ridge
        end do
        call dposv('U', r, 1, h, r, d, r, info)
        if (info /= 0) exit
      else
        call gm%factor(gs, free(z), spread(ridge, 1, r), err)
        if (err%failed()) exit
        call gm%chol%solve(d, err)
        if (err%failed()) exit
      end if
      ! Newton direction for phi is +d (phi's Hessian G_P G_P', gradient -f); backtrack
      t = 1.0_wp
      do k = 1, 60
        nt = nu + t*d
        phit = 0.5_wp*sum(project(nt)**2) + dot_product(es, nt)
        if (phit <= phi - 1.0e-4_wp*t*dot_product(f, d)) exit
        t = 0.5_wp*t
      end do
      if (k > 60) exit
      ! a step that leaves nu as it is: every further iteration would repeat this one exactly
      if (all(nt == nu)) exit
      nu = nt
      phi = phit
      z = project(nu)
    end do
    f = gs%times(z) - es
    lmin = 0.0_wp
    if (any(z > lo .and. z < hi)) then
      if (dense) then
        call gram(z, h)
        allocate (ev(r), work(max(64, 3*r)))
        call dsyev('N', 'U', r, h, r, ev, work, size(work), info)
        if (info == 0) lmin = max(ev(1), 0.0_wp)
      else
        lmin = smallest_eigenvalue()
      end if
    end if
    call gm%free()
    perr = norm2(f)/sqrt(max(lmin, tiny(1.0_wp)))
    if (.not. lmin > 0.0_wp) perr = merge(0.0_wp, huge(1.0_wp), norm2(f) == 0.0_wp)

  contains

    !> P(y - G' v).
    function project(v) result(zz)
      real(wp), intent(in) :: v(:)
      real(wp) :: zz(m)
      zz = min(max(y - gs%ttimes(v), lo), hi)
    end function project

    !> 1 on the columns where lo < x < hi, 0 elsewhere.
    function free(x) result(w)
      real(wp), intent(in) :: x(:)
      real(wp) :: w(m)
      w = merge(1.0_wp, 0.0_wp, x > lo .and. x < hi)
    end function free

    !> G_P G_P', P the columns where lo < x < hi (dense).
    subroutine gram(x, hh)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: hh(:, :)
      integer :: kk, a, b
      hh = 0.0_wp
      do kk = 1, m
        if (.not. (x(kk) > lo(kk) .and. x(kk) < hi(kk))) cycle
        do b = gs%ptr(kk), gs%ptr(kk + 1) - 1
          do a = gs%ptr(kk), gs%ptr(kk + 1) - 1
            hh(gs%row(a), gs%row(b)) = hh(gs%row(a), gs%row(b)) + gs%val(a)*gs%val(b)
          end do
        end do
      end do
    end subroutine gram

    !> lambda_min(G_P G_P') from below: inverse iteration with its sparse factor (0 when
    !! it is singular) from a start with a part along every eigenvector, the Rayleigh quotient
    !! less the residual |A v - rho v| (an eigenvalue lies within it), then certified: the
    !! factor of G_P G_P' - lm I must exist (positive definite: every eigenvalue above lm),
    !! else lm is quartered until it does (0 after ten tries).
    real(wp) function smallest_eigenvalue() result(lm)
      real(wp), allocatable :: v(:), av(:), wz(:)
      real(wp) :: rho, eta
      integer :: kk
      lm = 0.0_wp
      allocate (wz(m))
      wz = free(z)
      call gm%factor(gs, wz, spread(0.0_wp, 1, r), err)
      if (err%failed()) return
      allocate (v(r))
      v = [(1.0_wp + 0.5_wp*sin(real(kk, wp)), kk=1, r)]
      v = v/norm2(v)
      do kk = 1, 200
        call gm%chol%solve(v, err)
        if (err%failed()) return
        v = v/norm2(v)
        av = gs%times(wz*gs%ttimes(v))
        rho = dot_product(v, av)
        eta = norm2(av - rho*v)
        if (eta <= 1.0e-3_wp*rho) exit
      end do
      lm = max(rho - eta, 0.0_wp)
      do kk = 1, 10
        if (.not. lm > 0.0_wp) exit
        call gm%factor(gs, wz, spread(-lm, 1, r), err)
        if (.not. err%failed()) return
        lm = 0.25_wp*lm
      end do
      lm = 0.0_wp
    end function smallest_eigenvalue

  end subroutine project_feasible

end module error_estimate
