!> The a posteriori bound of the error of a contact force against the monolithic solution
!! of the same discrete problem (doc/method.md, "Method as implemented", accuracy bound),
!! with the projection on the feasible set of floating bodies.
module error_estimate
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use lapack, only: dsymv, dpotrf, dpotrs, dposv
  use condense, only: interface_t, body_condensed_t
  use contact_types, only: contact_result_t
  use equality_rows, only: gram_eigenvalues, stacked_rows
  implicit none (type, external)
  private

  public :: error_bound

contains

  !> A posteriori bound of the error of res%lam against the monolithic solution lam* of
  !! the same discrete problem: for the strongly convex QP min 1/2 l'Hl - c'l, l >= 0
  !! (H = F_1 + F_2, c = b_1 + b_2 - g0) and the natural residual
  !! r = l - max(0, l - (Hl - c)/L), |l - lam*| <= 2 (L/mu) |r| with L, mu the extreme
  !! eigenvalues of H (estimated by power and inverse iteration, kappa enlarged by 10%).
  !! Sets res%error_bound (relative to |lam|) and res%kappa.
  subroutine error_bound(contact_line, bodies, res)
    type(interface_t), intent(in) :: contact_line        !< contact line
    type(body_condensed_t), intent(in) :: bodies(2)      !< condensed bodies
    type(contact_result_t), intent(inout) :: res         !< lam in; error_bound, kappa out
    real(wp), allocatable :: H(:, :), A(:, :), g(:), r(:), x(:), y(:)
    real(wp) :: lmax, lmin, nl, perr
    integer :: m, i, k, info
    m = contact_line%m
    res%error_bound = 0.0_wp
    res%kappa = 1.0_wp
    if (m == 0) return
    allocate (H(m, m), A(m, m), g(m), r(m), x(m), y(m))
    H = bodies(1)%flex + bodies(2)%flex
    ! largest eigenvalue: power iteration (a lower estimate, enlarged below)
    do i = 1, m
      x(i) = 1.0_wp + 0.5_wp*sin(real(i, wp))
    end do
    x = x/norm2(x)
    lmax = 0.0_wp
    do k = 1, 60
      call dsymv('U', m, 1.0_wp, H, m, x, 1, 0.0_wp, y, 1)
      lmax = norm2(y)
      if (.not. lmax > 0.0_wp) exit
      x = y/lmax
    end do
    ! smallest eigenvalue: inverse iteration on the Cholesky factor of H
    A = H
    call dpotrf('U', m, A, m, info)
    if (info /= 0 .or. .not. lmax > 0.0_wp) then
      res%error_bound = huge(1.0_wp)
      res%kappa = huge(1.0_wp)
      return
    end if
    do i = 1, m
      x(i) = 1.0_wp + 0.5_wp*cos(real(3*i, wp))
    end do
    x = x/norm2(x)
    do k = 1, 60
      y = x
      call dpotrs('U', m, 1, A, m, y, m, info)
      x = y/norm2(y)
    end do
    call dsymv('U', m, 1.0_wp, H, m, x, 1, 0.0_wp, y, 1)
    lmin = dot_product(x, y)
    res%kappa = 1.1_wp*lmax/max(lmin, tiny(1.0_wp))
    if (.not. (ieee_is_finite(res%kappa) .and. ieee_is_finite(lmax) .and. lmax > 0.0_wp)) then
      ! out of the range of double precision: no bound can be given
      res%kappa = huge(1.0_wp)
      res%error_bound = huge(1.0_wp)
      return
    end if
    ! natural residual of the mean contact force
    call dsymv('U', m, 1.0_wp, H, m, res%lam, 1, 0.0_wp, g, 1)
    g = g - (bodies(1)%b + bodies(2)%b - contact_line%g0)
    if (bodies(1)%nrig + bodies(2)%nrig > 0) then
      ! floating bodies: the feasible set is {l >= 0, G l = e}, and the bound holds with the
      ! projection on it (the proof only uses the projection's variational inequality and
      ! the strong convexity of the objective on R^m); the projection's own inaccuracy is added
      call project_feasible(bodies, res%lam - g/lmax, y, perr)
      r = res%lam - y
    else
      r = res%lam - max(0.0_wp, res%lam - g/lmax)
      perr = 0.0_wp
    end if
    nl = norm2(res%lam)
    ! the residual itself is computed in floating point: add its rounding level
    if (.not. perr < 0.01_wp*huge(1.0_wp)) then
      ! the projection on the feasible set is not known to any accuracy: no bound
      res%error_bound = huge(1.0_wp)
    else if (nl > 0.0_wp) then
      res%error_bound = 2.0_wp*res%kappa*((norm2(r) + perr)/nl + 10.0_wp*real(m, wp)*epsilon(1.0_wp))
    else
      res%error_bound = merge(0.0_wp, huge(1.0_wp), norm2(r) == 0.0_wp)
    end if
  end subroutine error_bound

  !> z = the Euclidean projection of y on {l >= 0, G l = e} (G, e: both bodies' equilibrium
  !! rows, stacked): z = max(0, y - G'nu) with nu the minimiser of the convex, piecewise
  !! quadratic phi(nu) = 1/2 |max(0, y - G'nu)|^2 + e'nu (r <= 6 unknowns), by Newton steps on
  !! the current positive set (Hessian G_P G_P', a small ridge when it is singular) with a
  !! backtracking line search on phi: exact once the positive set is right, whatever the
  !! conditioning of G on it. perr bounds |z - exact projection| by the equilibrium left,
  !! |G z - e| / sqrt(lambda_min(G_P G_P')).
  subroutine project_feasible(bodies, y, z, perr)
    type(body_condensed_t), intent(in) :: bodies(2)
    real(wp), intent(in) :: y(:)
    real(wp), allocatable, intent(out) :: z(:)
    real(wp), intent(out) :: perr
    real(wp), allocatable :: gs(:, :), es(:), nu(:), f(:), h(:, :), d(:), nt(:), gp(:, :)
    real(wp) :: phi, phit, t, ridge, lmin
    integer :: m, r, it, k, info
    m = size(y)
    call stacked_rows(bodies, gs, es)
    r = size(es)
    allocate (nu(r), f(r), h(r, r), d(r), nt(r))
    nu = 0.0_wp
    z = max(y - matmul(nu, gs), 0.0_wp)
    phi = 0.5_wp*sum(z**2) + dot_product(es, nu)
    ridge = 1.0e-14_wp*maxval(sum(gs**2, dim=2))
    do it = 1, 200
      f = matmul(gs, z) - es           ! = -grad phi
      if (norm2(f) <= 1.0e-15_wp*max(norm2(es), tiny(1.0_wp))) exit
      gp = gs(:, pack([(k, k=1, m)], z > 0.0_wp))
      h = matmul(gp, transpose(gp))
      do k = 1, r
        h(k, k) = h(k, k) + ridge
      end do
      d = f
      call dposv('U', r, 1, h, r, d, r, info)
      if (info /= 0) exit
      ! Newton direction for phi is +d (phi's Hessian G_P G_P', gradient -f); backtrack
      t = 1.0_wp
      do k = 1, 60
        nt = nu + t*d
        phit = 0.5_wp*sum(max(y - matmul(nt, gs), 0.0_wp)**2) + dot_product(es, nt)
        if (phit <= phi - 1.0e-4_wp*t*dot_product(f, d)) exit
        t = 0.5_wp*t
      end do
      if (k > 60) exit
      nu = nt
      phi = phit
      z = max(y - matmul(nu, gs), 0.0_wp)
    end do
    f = matmul(gs, z) - es
    gp = gs(:, pack([(k, k=1, m)], z > 0.0_wp))
    lmin = 0.0_wp
    if (size(gp, 2) > 0) lmin = minval(gram_eigenvalues(gp))
    perr = norm2(f)/sqrt(max(lmin, tiny(1.0_wp)))
    if (.not. lmin > 0.0_wp) perr = merge(0.0_wp, huge(1.0_wp), norm2(f) == 0.0_wp)
  end subroutine project_feasible

end module error_estimate
