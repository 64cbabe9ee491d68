!> Unit tests of module mortar: matching and non-matching flat lines (identity, partition of
!! unity, linear reproduction, the uniform-pressure patch test), a master at distance h, a
!! curved slave over a flat master (g0 against the normal distance, second-order in h),
!! removed nodes, partial overlap, bad input, and the build time at 100k x 130k segments;
!! the contract's consistency diagnostic, the dispatch by dimension, and the node frames.
program test_mortar
  use kinds, only: wp
  use strings, only: i2s, fixed
  use mortar, only: mortar_t, mortar_build, mortar_consistency
  use space, only: frame_of
  use testing, only: report, report_le, test_summary, error_parts
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)

  real(wp), parameter :: tol = 1.0e-13_wp

  call test_matching()
  call test_nonmatching(0.0_wp, 0.0_wp, [0.0_wp, 0.0_wp], 'flat, touching')
  call test_nonmatching(0.05_wp, 0.0_wp, [0.0_wp, 0.0_wp], 'flat, master at h = 0.05')
  call test_nonmatching(0.05_wp, 0.4_wp, [3.0_wp, -2.0_wp], 'rotated 0.4 rad and moved, h = 0.05')
  call test_curved()
  call test_curved_master()
  call test_removal()
  call test_partial()
  call test_closed_loops()
  call test_bad_input()
  call test_dispatch()
  call test_frames()
  call test_timing()

  call test_summary()

contains

  !> Deterministic pseudo-random number in [-0.5, 0.5) for integer pair (i, j).
  pure real(wp) function hash01(i, j)
    integer, intent(in) :: i, j
    real(wp) :: v
    v = sin(12.9898_wp * real(i, wp) + 78.233_wp * real(j, wp) + 0.5_wp) * 43758.5453_wp
    hash01 = v - real(floor(v), wp) - 0.5_wp
  end function hash01

  !> n+1 positions from a to b, interior ones moved by up to +-amp of a spacing.
  function positions(n, a, b, amp, seed) result(u)
    integer, intent(in) :: n, seed
    real(wp), intent(in) :: a, b, amp
    real(wp) :: u(0:n)
    integer :: k
    do k = 0, n
      u(k) = a + (b - a) * real(k, wp) / real(n, wp)
      if (k > 0 .and. k < n) u(k) = u(k) + amp * (b - a) / real(n, wp) * hash01(k, seed)
    end do
  end function positions

  !> Two parallel lines, rotated by theta and moved by off: the slave at v = 0 on positions
  !! us (body below, slave node id k+1 at us(k), one unused node), the master at v = h on
  !! positions um (body above, master node id nm+2-k at um(k), node 1 unused). The slave
  !! edges are listed in a scrambled order.
  subroutine two_lines(us, um, h, theta, off, xs, es, xm, em)
    real(wp), intent(in) :: us(0:), um(0:), h, theta, off(2)
    real(wp), allocatable, intent(out) :: xs(:, :), xm(:, :)
    integer, allocatable, intent(out) :: es(:, :), em(:, :)
    integer :: ns, nm, k, e, mult
    ns = size(us) - 1
    nm = size(um) - 1
    allocate (xs(2, ns + 2), es(2, ns), xm(2, nm + 2), em(2, nm))
    do k = 0, ns
      xs(:, k + 1) = lift(us(k), 0.0_wp, theta, off)
    end do
    xs(:, ns + 2) = lift(0.5_wp, -1.0_wp, theta, off)
    mult = 5                              ! a multiplier prime to ns scrambles the edge order
    if (mod(ns, 5) == 0) mult = 3
    if (mod(ns, 15) == 0) mult = 7
    do k = 0, ns - 1
      e = 1 + mod(mult * k, ns)
      es(:, e) = [k + 2, k + 1]
    end do
    xm(:, 1) = lift(0.5_wp, h + 1.0_wp, theta, off)
    do k = 0, nm
      xm(:, nm + 2 - k) = lift(um(k), h, theta, off)
    end do
    do k = 0, nm - 1
      em(:, k + 1) = [nm + 2 - k, nm + 1 - k]
    end do
  end subroutine two_lines

  !> The point (u, v) of the rotated (theta) and moved (off) frame.
  pure function lift(u, v, theta, off) result(x)
    real(wp), intent(in) :: u, v, theta, off(2)
    real(wp) :: x(2)
    x = off + [cos(theta) * u - sin(theta) * v, sin(theta) * u + cos(theta) * v]
  end function lift

  !> Tributary lengths of positions u.
  function tributary(u) result(t)
    real(wp), intent(in) :: u(0:)
    real(wp) :: t(0:size(u) - 1)
    integer :: k, n
    n = size(u) - 1
    t = 0.0_wp
    do k = 1, n
      t(k - 1) = t(k - 1) + 0.5_wp * (u(k) - u(k - 1))
      t(k) = t(k) + 0.5_wp * (u(k) - u(k - 1))
    end do
  end function tributary

  real(wp) function slave_sum(mt, j)
    type(mortar_t), intent(in) :: mt
    integer, intent(in) :: j
    slave_sum = sum(mt%sval(mt%sptr(j):mt%sptr(j + 1) - 1))
  end function slave_sum

  real(wp) function master_sum(mt, j)
    type(mortar_t), intent(in) :: mt
    integer, intent(in) :: j
    master_sum = sum(mt%mval(mt%mptr(j):mt%mptr(j + 1) - 1))
  end function master_sum

  !> sum_l w_jl x_l of row j of one side's weights in compressed rows (ptr, nod, val: the
  !! master's mptr, mnod, mval or the slave's sptr, snod, sval) over its node coordinates x.
  function row_point(ptr, nod, val, j, x) result(p)
    integer, intent(in) :: ptr(:), nod(:), j
    real(wp), intent(in) :: val(:), x(:, :)
    real(wp) :: p(2)
    integer :: e
    p = 0.0_wp
    do e = ptr(j), ptr(j + 1) - 1
      p = p + val(e) * x(:, nod(e))
    end do
  end function row_point

  !> Slave weight of node k in row j (0 if absent).
  real(wp) function slave_weight(mt, j, k)
    type(mortar_t), intent(in) :: mt
    integer, intent(in) :: j, k
    integer :: e
    slave_weight = 0.0_wp
    do e = mt%sptr(j), mt%sptr(j + 1) - 1
      if (mt%snod(e) == k) slave_weight = slave_weight + mt%sval(e)
    end do
  end function slave_weight

  !> Nodal forces of multipliers lam on one side, from its weights in compressed rows
  !! (ptr, nod, val: the master's mptr, mnod, mval or the slave's sptr, snod, sval):
  !! f_l = sum_j lam_j w_jl.
  function side_forces(ptr, nod, val, lam, nnode) result(f)
    integer, intent(in) :: ptr(:), nod(:)
    real(wp), intent(in) :: val(:), lam(:)
    integer, intent(in) :: nnode
    real(wp) :: f(nnode)
    integer :: j, e
    f = 0.0_wp
    do j = 1, size(lam)
      do e = ptr(j), ptr(j + 1) - 1
        f(nod(e)) = f(nod(e)) + lam(j) * val(e)
      end do
    end do
  end function side_forces

  !> Build and stop the test program if it fails.
  subroutine build_ok(xs, es, removable, xm, em, mt, what)
    real(wp), intent(in) :: xs(:, :), xm(:, :)
    integer, intent(in) :: es(:, :), em(:, :)
    logical, intent(in) :: removable(:)
    type(mortar_t), intent(out) :: mt
    character(len=*), intent(in) :: what
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    call mortar_build(xs, es, removable, xm, em, mt, err)
    call error_parts(err, info, msg)
    call report(info == 0 .and. msg == '', what//': mortar_build succeeds')
    if (info /= 0) then
      write (*, '(a)') 'FAIL  '//what//': '//trim(msg)
      call test_summary()
      error stop 1
    end if
  end subroutine build_ok

  !> Matching flat lines: M = D, one master entry of weight 1 per row (the rest rounding),
  !! D = tributary lengths, g0 = 0, normals (0, 1), arc length from the chain start.
  subroutine test_matching()
    integer, parameter :: n = 6
    real(wp) :: u(0:n), t(0:n), err_m, err_s, err_d, err_g, err_n, err_a, w
    real(wp), allocatable :: xs(:, :), xm(:, :)
    integer, allocatable :: es(:, :), em(:, :)
    type(mortar_t) :: mt
    integer :: j, k, e, nbig
    u = positions(n, 0.0_wp, 1.0_wp, 0.6_wp, 1)
    t = tributary(u)
    call two_lines(u, u, 0.0_wp, 0.0_wp, [0.0_wp, 0.0_wp], xs, es, xm, em)
    call build_ok(xs, es, [(.false., k = 1, size(xs, 2))], xm, em, mt, 'matching')
    call report(mt%m == n + 1, 'matching: one row per slave node')
    err_m = 0.0_wp; err_s = 0.0_wp; err_d = 0.0_wp; err_g = 0.0_wp; err_n = 0.0_wp; err_a = 0.0_wp
    nbig = 0
    do j = 1, mt%m
      k = n - (j - 1)                ! the slave chain runs from x = 1 to x = 0
      if (mt%snode(j) /= k + 1) nbig = nbig + 1000
      err_s = max(err_s, abs(slave_sum(mt, j) - 1.0_wp))
      if (mt%sptr(j + 1) - mt%sptr(j) /= 1 .or. mt%snod(mt%sptr(j)) /= k + 1) nbig = nbig + 1
      do e = mt%mptr(j), mt%mptr(j + 1) - 1
        w = mt%mval(e)
        if (mt%mnod(e) == n + 2 - k) then
          err_m = max(err_m, abs(w - 1.0_wp))
        else
          err_m = max(err_m, abs(w))
        end if
      end do
      if (.not. any(mt%mnod(mt%mptr(j):mt%mptr(j + 1) - 1) == n + 2 - k)) nbig = nbig + 1
      err_d = max(err_d, abs(mt%d(j) - t(k)))
      err_g = max(err_g, abs(mt%g0(j)))
      err_n = max(err_n, norm2(mt%normal(:, j) - [0.0_wp, 1.0_wp]))
      err_a = max(err_a, abs(mt%s(j) - (1.0_wp - u(k))))
    end do
    call report(nbig == 0, 'matching: rows in chain order, own slave node only, its matching master node present')
    call report_le(err_m, tol, 'matching: M/D = identity')
    call report_le(err_s, tol, 'matching: slave weight 1')
    call report_le(err_d, tol, 'matching: D = tributary length')
    call report_le(err_g, tol, 'matching: g0 = 0')
    call report_le(err_n, tol, 'matching: normals (0, 1)')
    call report_le(err_a, tol, 'matching: arc length from the chain start')
    call mortar_consistency(mt, w, k)
    call report(k == n + 1, 'matching: consistency measured on every row (all fully covered)')
    call report_le(w, tol, 'matching: max |sum_l M_jl - D_jj| / D_jj = 0')
  end subroutine test_matching

  !> Slave 7 segments, master 5, both perturbed, master at normal distance h, the whole
  !! scene rotated by theta and moved by off.
  subroutine test_nonmatching(h, theta, off, what)
    real(wp), intent(in) :: h, theta, off(2)
    character(len=*), intent(in) :: what
    integer, parameter :: ns = 7, nm = 5
    real(wp) :: us(0:ns), um(0:nm), ts(0:ns), tm(0:nm), e_pu, e_ws, e_lin, e_g, e_n, e_d, nrm(2), tng(2), &
                integral, f_m(nm + 2), p
    real(wp), allocatable :: xs(:, :), xm(:, :), lam(:)
    integer, allocatable :: es(:, :), em(:, :)
    type(mortar_t) :: mt
    integer :: j, k, e
    us = positions(ns, 0.0_wp, 1.0_wp, 0.7_wp, 2)
    um = positions(nm, 0.0_wp, 1.0_wp, 0.7_wp, 3)
    ts = tributary(us)
    tm = tributary(um)
    call two_lines(us, um, h, theta, off, xs, es, xm, em)
    call build_ok(xs, es, [(.false., k = 1, size(xs, 2))], xm, em, mt, what)
    call report(mt%m == ns + 1, what//': one row per slave node')
    nrm = [-sin(theta), cos(theta)]
    tng = [cos(theta), sin(theta)]
    e_pu = 0.0_wp; e_ws = 0.0_wp; e_lin = 0.0_wp; e_g = 0.0_wp; e_n = 0.0_wp; e_d = 0.0_wp
    integral = 0.0_wp
    do j = 1, mt%m
      k = mt%snode(j) - 1
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp))
      e_ws = max(e_ws, abs(slave_sum(mt, j) - 1.0_wp))
      ! Linear reproduction on flat geometry: sum_l wm x^m_l = x^s_j + h n_j.
      e_lin = max(e_lin, norm2(row_point(mt%mptr, mt%mnod, mt%mval, j, xm) - xs(:, k + 1) - h * nrm))
      e_g = max(e_g, abs(mt%g0(j) - h))
      e_n = max(e_n, norm2(mt%normal(:, j) - nrm))
      e_d = max(e_d, abs(mt%d(j) - ts(k)))
      ! int f(x^m(pi(x))) ds with f = 2 + 3 (position along the line): sum_j D_j sum_l wm f(x^m_l).
      do e = mt%mptr(j), mt%mptr(j + 1) - 1
        integral = integral + mt%d(j) * mt%mval(e) * (2.0_wp + 3.0_wp * dot_product(xm(:, mt%mnod(e)) - off, tng))
      end do
    end do
    call report_le(e_pu, tol, what//': partition of unity sum_l M_jl/D_jj = 1')
    call report_le(e_ws, tol, what//': slave weight 1')
    call report_le(e_lin, tol, what//': sum_l (M_jl/D_jj) x^m_l = x^s_j + h n_j')
    call report_le(abs(integral - 3.5_wp), tol, what//': sum_j D_jj sum_l (M_jl/D_jj) f(x^m_l) = int f for f linear')
    call report_le(e_g, tol, what//': g0 = h on every row')
    call report_le(e_n, tol, what//': normals')
    call report_le(e_d, tol, what//': D = slave tributary length')
    call mortar_consistency(mt, e_pu, k)
    call report(k == ns + 1, what//': consistency measured on every row')
    call report_le(e_pu, tol, what//': max |sum_l M_jl - D_jj| / D_jj = 0 (flat)')
    ! Uniform pressure p: lam_j = p D_jj gives the master the consistent nodal forces p * tributary.
    p = 7.0_wp
    lam = p * mt%d
    f_m = side_forces(mt%mptr, mt%mnod, mt%mval, lam, nm + 2)
    call report_le(maxval([(abs(f_m(nm + 2 - k) - p * tm(k)), k = 0, nm)]) / p, tol, &
                   what//': uniform pressure passes exactly (patch test)')
  end subroutine test_nonmatching

  !> A polygon on a circle (radius R, centre (0, R)) over a flat master at y = 0 touching at
  !! x = 0. Interior normals are radial (inverse-length weighting), g0 approaches the
  !! distance along the normal to y = 0 at second order in h.
  subroutine test_curved()
    real(wp), parameter :: r = 1.0_wp
    real(wp) :: err(2), hmax(2), e_n, e_pu, e_ws, e_end
    integer :: lev
    do lev = 1, 2
      call curved_case(r, 12 * lev, err(lev), hmax(lev), e_n, e_pu, e_ws, e_end)
      call report_le(e_n, tol, 'curved n = '//i2s(12 * lev)//': interior normals radial (x - c)/R')
      call report_le(e_end, tol, 'curved n = '//i2s(12 * lev)//': end normals = their edge''s normal')
      call report_le(e_pu, tol, 'curved n = '//i2s(12 * lev)//': partition of unity')
      call report_le(e_ws, tol, 'curved n = '//i2s(12 * lev)//': slave weight 1')
      ! The error is O(h^2/R): the dual average of the normal distance d(s) is
      ! d(s_j) - d'' h^2/12 + ... with d'' ~ 1/R, and the chord lies inside the circle by
      ! up to h^2/(8R), which adds about + h^2/(12R) to the average. The two cancel for
      ! uniform spacing; with this spacing (+-25% perturbed) the error measured is about
      ! h^2/150R. Tolerance h^2/(20R): the vertical gap instead of the normal distance, or
      ! a first-order error, would exceed it.
      call report_le(err(lev), hmax(lev)**2 / (20.0_wp * r), 'curved n = '//i2s(12 * lev)// &
                     ': |g0 - normal distance to y = 0| <= h^2/(20R)')
    end do
    call report(err(2) <= err(1) / 3.0_wp, 'curved: g0 error falls at second order (ratio '// &
                fixed(err(1) / err(2), '(f0.2)')//' >= 3 on halving h)')
  end subroutine test_curved

  !> One polygon of the curved test: n segments on the circle of radius r.
  subroutine curved_case(r, n, emax, hm, e_n, e_pu, e_ws, e_end)
    real(wp), intent(in) :: r
    integer, intent(in) :: n
    real(wp), intent(out) :: emax, hm, e_n, e_pu, e_ws, e_end
    real(wp) :: phi(0:n), um(0:9), c(2), dist, x(2), en(2)
    real(wp), allocatable :: xs(:, :), xm(:, :)
    integer, allocatable :: es(:, :), em(:, :)
    type(mortar_t) :: mt
    integer :: k, j
    phi = positions(n, -0.3_wp, 0.3_wp, 0.5_wp, 4)
    um = positions(9, -1.0_wp, 1.0_wp, 0.5_wp, 5)
    c = [0.0_wp, r]
    allocate (xs(2, n + 1), es(2, n), xm(2, 10), em(2, 9))
    do k = 0, n
      xs(:, k + 1) = c + r * [sin(phi(k)), -cos(phi(k))]
    end do
    do k = 1, n
      es(:, k) = [k, k + 1]          ! counterclockwise: the disk on the left
    end do
    do k = 0, 9
      xm(:, k + 1) = [um(k), 0.0_wp]
    end do
    do k = 1, 9
      em(:, k) = [k + 1, k]          ! right to left: the master body below
    end do
    call build_ok(xs, es, [(.false., k = 1, n + 1)], xm, em, mt, 'curved n = '//i2s(n))
    call report(mt%m == n + 1, 'curved n = '//i2s(n)//': every slave node has a row')
    hm = 0.0_wp
    do k = 1, n
      hm = max(hm, norm2(xs(:, k + 1) - xs(:, k)))
    end do
    emax = 0.0_wp; e_n = 0.0_wp; e_pu = 0.0_wp; e_ws = 0.0_wp; e_end = 0.0_wp
    do j = 1, mt%m
      k = mt%snode(j)
      x = xs(:, k)
      ! distance from x along its nodal normal to y = 0
      dist = -x(2) / mt%normal(2, j)
      emax = max(emax, abs(mt%g0(j) - dist))
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp))
      e_ws = max(e_ws, abs(slave_sum(mt, j) - 1.0_wp))
      if (k == 1 .or. k == n + 1) then
        if (k == 1) en = xs(:, 2) - xs(:, 1)
        if (k == n + 1) en = xs(:, n + 1) - xs(:, n)
        en = [en(2), -en(1)] / norm2(en)
        e_end = max(e_end, norm2(mt%normal(:, j) - en))
      else
        e_n = max(e_n, norm2(mt%normal(:, j) - (x - c) / r))
      end if
    end do
  end subroutine curved_case

  !> A flat slave (y = 0, body above) over a curved master: a polygon on nearly the whole
  !! circle of radius R centred at (0, -R - h), so its lower half lies under the slave too
  !! but faces away and must be ignored. g0 against the vertical gap R + h - sqrt(R^2 - x^2).
  subroutine test_curved_master()
    integer, parameter :: ns = 10, nm = 240
    real(wp), parameter :: r = 1.0_wp, h = 0.01_wp
    real(wp) :: us(0:ns), th(0:nm), xs(2, ns + 1), xm(2, nm + 1), e_pu, e_ws, e_g, e_v, hm, x, avg
    integer :: es(2, ns), em(2, nm), k, j
    type(mortar_t) :: mt
    us = positions(ns, -0.5_wp, 0.5_wp, 0.5_wp, 14)
    do k = 0, ns
      xs(:, k + 1) = [us(k), 0.0_wp]
    end do
    do k = 1, ns
      es(:, k) = [k, k + 1]            ! left to right: the slave body above
    end do
    ! counterclockwise (the disk on the left) from just right of the bottom round to just left of it
    th = positions(nm, -0.5_wp * acos(-1.0_wp) + 0.2_wp, 1.5_wp * acos(-1.0_wp) - 0.2_wp, 0.4_wp, 15)
    do k = 0, nm
      xm(:, k + 1) = [0.0_wp, -r - h] + r * [cos(th(k)), sin(th(k))]
    end do
    do k = 1, nm
      em(:, k) = [k, k + 1]
    end do
    call build_ok(xs, es, [(.false., k = 1, ns + 1)], xm, em, mt, 'curved master')
    call report(mt%m == ns + 1, 'curved master: every slave node has a row')
    hm = 0.0_wp
    do k = 1, nm
      hm = max(hm, norm2(xm(:, k + 1) - xm(:, k)))
    end do
    e_pu = 0.0_wp; e_ws = 0.0_wp; e_g = 0.0_wp; e_v = 0.0_wp
    do j = 1, mt%m
      k = mt%snode(j) - 1
      x = xs(1, mt%snode(j))
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp))
      e_ws = max(e_ws, abs(slave_sum(mt, j) - 1.0_wp))
      e_v = max(e_v, abs(mt%g0(j) - circle_gap(x, r, h)))
      ! the dual average int Phi_j g ds / D_jj of the exact gap, by composite Gauss quadrature
      avg = 0.0_wp
      if (k > 0) avg = avg + dual_integral(x, us(k - 1), r, h)
      if (k < ns) avg = avg + dual_integral(x, us(k + 1), r, h)
      e_g = max(e_g, abs(mt%g0(j) - avg / mt%d(j)))
    end do
    call report_le(e_pu, tol, 'curved master: partition of unity (the back half not counted)')
    call report_le(e_ws, tol, 'curved master: slave weight 1')
    ! g0 is the dual average of the gap to the polygon, whose chords lie inside the circle by
    ! at most hm^2/(8R); int |Phi_j| ds = 5/3 D_jj, so the difference is below 5/3 hm^2/(8R).
    call report_le(e_g, 5.0_wp / 3.0_wp * hm**2 / (8.0_wp * r), &
                   'curved master: |g0 - int Phi_j (exact gap) ds / D_jj| <= 5/3 hm^2/(8R)')
    ! Against the gap at the node itself the dual average differs by -(a^2 - ab + b^2)/(12R)
    ! (a, b the node's two spacings, gap'' = 1/R), at most h_s^2/(12R) with h_s the largest
    ! spacing (1.25/ns here); 10% added for the higher-order terms.
    call report_le(e_v, 5.0_wp / 3.0_wp * hm**2 / (8.0_wp * r) + 1.1_wp * (1.25_wp / real(ns, wp))**2 / (12.0_wp * r), &
                   'curved master: |g0 - vertical gap at the node| <= 5/3 hm^2/(8R) + 1.1 h_s^2/(12R)')
  end subroutine test_curved_master

  !> Vertical gap from (x, 0) down to the circle of radius r centred at (0, -r - h).
  pure real(wp) function circle_gap(x, r, h) result(g)
    real(wp), intent(in) :: x, r, h
    g = r + h - sqrt(r**2 - x**2)
  end function circle_gap

  !> int Phi g ds over the flat slave segment from xa (Phi = 2) to xb (Phi = -1), g the
  !! circle gap, by 40 x 5-point Gauss (an independent check of the module's quadrature).
  pure real(wp) function dual_integral(xa, xb, r, h) result(v)
    real(wp), intent(in) :: xa, xb, r, h
    real(wp), parameter :: z(5) = [-0.9061798459386640_wp, -0.5384693101056831_wp, 0.0_wp, &
                                   0.5384693101056831_wp, 0.9061798459386640_wp]
    real(wp), parameter :: w(5) = [0.2369268850561891_wp, 0.4786286704993665_wp, 0.5688888888888889_wp, &
                                   0.4786286704993665_wp, 0.2369268850561891_wp]
    integer :: i, g
    real(wp) :: t
    v = 0.0_wp
    do i = 1, 40
      do g = 1, 5
        t = (real(i - 1, wp) + 0.5_wp * (1.0_wp + z(g))) / 40.0_wp
        v = v + w(g) / 80.0_wp * (2.0_wp - 3.0_wp * t) * circle_gap(xa + t * (xb - xa), r, h)
      end do
    end do
    v = v * abs(xb - xa)
  end function dual_integral

  !> Removable slave nodes: no row; the neighbour's function is 1 on the shared segment and
  !! its row carries the removed node with weight (L/2)/D_jj; rows stay invariant under
  !! translation and the patch test still passes.
  subroutine test_removal()
    integer, parameter :: ns = 7, nm = 5
    real(wp), parameter :: h = 0.05_wp, p = 3.0_wp
    real(wp) :: us(0:ns), um(0:nm), ts(0:ns), tm(0:nm), e_inv, e_g, e_d, f_m(nm + 2)
    real(wp), allocatable :: xs(:, :), xm(:, :), lam(:), f_s(:)
    integer, allocatable :: es(:, :), em(:, :)
    logical, allocatable :: rem(:)
    type(mortar_t) :: mt
    integer :: j, k, case_, rnode, nb(2), ok
    us = positions(ns, 0.0_wp, 1.0_wp, 0.7_wp, 6)
    um = positions(nm, 0.0_wp, 1.0_wp, 0.7_wp, 7)
    ts = tributary(us)
    tm = tributary(um)
    call two_lines(us, um, h, 0.0_wp, [0.0_wp, 0.0_wp], xs, es, xm, em)
    do case_ = 1, 2
      rnode = merge(1, 5, case_ == 1)            ! slave node 1 (x = 0, a chain end) or interior node 5
      allocate (rem(size(xs, 2)))
      rem = .false.
      rem(rnode) = .true.
      call build_ok(xs, es, rem, xm, em, mt, 'removal of node '//i2s(rnode))
      call report(mt%m == ns .and. .not. any(mt%snode == rnode), 'removal of node '//i2s(rnode)//': no row for it')
      nb = [rnode - 1, rnode + 1]                 ! slave neighbours (ids k+1 at us(k))
      ok = 0
      e_inv = 0.0_wp; e_g = 0.0_wp; e_d = 0.0_wp
      do j = 1, mt%m
        k = mt%snode(j)
        if (mt%snod(mt%sptr(j)) /= k .or. abs(mt%sval(mt%sptr(j)) - 1.0_wp) > tol) ok = ok + 1
        if (k == nb(1) .or. k == nb(2)) then
          ! extra entry (L/2)/D_jj, L the shared segment
          if (abs(slave_weight(mt, j, rnode) - 0.5_wp * abs(us(k - 1) - us(rnode - 1)) / ts(k - 1)) > tol) ok = ok + 100
          if (mt%sptr(j + 1) - mt%sptr(j) /= 2) ok = ok + 1000
        else
          if (mt%sptr(j + 1) - mt%sptr(j) /= 1) ok = ok + 10000
        end if
        e_inv = max(e_inv, abs(slave_sum(mt, j) - master_sum(mt, j)))
        ! weighted gap of a uniform gap h: h times the row's weight sum (1 + (L/2)/D_jj next to r)
        e_g = max(e_g, abs(mt%g0(j) - h * slave_sum(mt, j)), &
                  norm2(row_point(mt%mptr, mt%mnod, mt%mval, j, xm) - row_point(mt%sptr, mt%snod, mt%sval, j, xs) &
                        - [0.0_wp, h * slave_sum(mt, j)]))
        e_d = max(e_d, abs(mt%d(j) - ts(k - 1)))
      end do
      call report(ok == 0, 'removal of node '//i2s(rnode)//': own weight 1 first; neighbours carry it with '// &
                  'weight (L/2)/D_jj, other rows do not (code '//i2s(ok)//')')
      call report_le(e_inv, tol, 'removal of node '//i2s(rnode)//': sum of slave weights = sum of master weights')
      call report_le(e_g, tol, 'removal of node '//i2s(rnode)//': g0 = h * (sum of weights) = the row at u = 0')
      call report_le(e_d, tol, 'removal of node '//i2s(rnode)//': D_jj unchanged (int N_j)')
      ! Uniform pressure p: lam_j = p D_jj gives both bodies their consistent nodal forces,
      ! the removed node's share included (it comes through the neighbours' extra entries).
      lam = p * mt%d
      f_m = side_forces(mt%mptr, mt%mnod, mt%mval, lam, nm + 2)
      f_s = side_forces(mt%sptr, mt%snod, mt%sval, lam, size(xs, 2))
      call report_le(maxval([(abs(p * tm(k) - f_m(nm + 2 - k)), k = 0, nm)]) / p, tol, &
                     'removal of node '//i2s(rnode)//': uniform pressure reaches the master exactly (patch test)')
      call report_le(maxval([(abs(p * ts(k) - f_s(k + 1)), k = 0, ns)]) / p, tol, &
                     'removal of node '//i2s(rnode)//': and the slave, removed node included')
      deallocate (rem)
    end do
  end subroutine test_removal

  !> Slave longer than the master: rows only where the master is; the end row is integrated
  !! over its covered part (known weights); g0 = h throughout. Master longer than the slave
  !! at both ends: every slave node has a row, partition of unity.
  subroutine test_partial()
    real(wp), parameter :: h = 0.02_wp
    real(wp) :: us(0:10), um(0:4), us2(0:6), um2(0:7), e_inv, e_g, xmax, c, l, w_own, w_r
    real(wp), allocatable :: xs(:, :), xm(:, :)
    integer, allocatable :: es(:, :), em(:, :)
    type(mortar_t) :: mt
    integer :: j, k, jend, bad
    us = positions(10, 0.0_wp, 2.0_wp, 0.0_wp, 8)     ! slave nodes every 0.2 on [0, 2]
    um = positions(4, -0.13_wp, 1.03_wp, 0.5_wp, 9)   ! master on [-0.13, 1.03]
    call two_lines(us, um, h, 0.0_wp, [0.0_wp, 0.0_wp], xs, es, xm, em)
    call build_ok(xs, es, [(.false., k = 1, size(xs, 2))], xm, em, mt, 'slave longer')
    call report(mt%m == 6, 'slave longer: rows for the 6 slave nodes under the master only (got '//i2s(mt%m)//')')
    xmax = -1.0_wp
    e_inv = 0.0_wp; e_g = 0.0_wp
    jend = 0
    do j = 1, mt%m
      xmax = max(xmax, xs(1, mt%snode(j)))
      if (mt%snode(j) == 6) jend = j          ! node 6 at x = 1.0, the last one under the master
      e_inv = max(e_inv, abs(slave_sum(mt, j) - master_sum(mt, j)))
      e_g = max(e_g, abs(mt%g0(j) - h * slave_sum(mt, j)))
    end do
    call report(xmax <= 1.03_wp, 'slave longer: no row beyond the master''s end')
    call report_le(e_inv, tol, 'slave longer: sum of slave weights = sum of master weights')
    call report_le(e_g, tol, 'slave longer: g0 = h * (sum of weights) on every row, the end row too')
    ! End row at x = 1: segment to x = 1.2 covered over c = 0.03; its function is 1 there.
    c = 0.03_wp
    l = 0.2_wp
    w_own = (0.5_wp * l + (c - c**2 / (2.0_wp * l))) / l
    w_r = (c**2 / (2.0_wp * l)) / l
    call report(jend > 0, 'slave longer: node at x = 1 has a row')
    if (jend > 0) then
      call report_le(abs(slave_weight(mt, jend, 6) - w_own), tol, 'slave longer: end row own weight '// &
                     '(L/2 + int_0^c N_j)/D over the covered part')
      call report_le(abs(slave_weight(mt, jend, 7) - w_r), tol, 'slave longer: end row weight of the uncovered '// &
                     'neighbour int_0^c N_r / D')
      call report_le(abs(mt%d(jend) - l), tol, 'slave longer: end row D = full tributary length')
    end if

    us2 = positions(6, 0.0_wp, 1.0_wp, 0.6_wp, 10)
    um2 = positions(7, -0.37_wp, 1.41_wp, 0.6_wp, 11)
    call two_lines(us2, um2, h, 0.2_wp, [1.0_wp, 1.0_wp], xs, es, xm, em)
    call build_ok(xs, es, [(.false., k = 1, size(xs, 2))], xm, em, mt, 'master longer')
    bad = 0
    e_inv = 0.0_wp
    do j = 1, mt%m
      e_inv = max(e_inv, abs(master_sum(mt, j) - 1.0_wp), abs(slave_sum(mt, j) - 1.0_wp), abs(mt%g0(j) - h))
    end do
    call report(mt%m == 7, 'master longer: every slave node has a row')
    call report_le(e_inv, tol, 'master longer: partition of unity, slave weight 1, g0 = h')
  end subroutine test_partial

  !> Closed loops: a pin of radius 1 (24 nodes) in a hole of radius 1.1 (37 nodes, turned
  !! by 0.05 rad), each rim one closed loop listed from an arbitrary edge; then the hole as
  !! the slave (48 nodes) and the pin as the master. Every slave node carries a row with the
  !! partition of unity (slave and master weights sum to 1), D = the chord of the uniform
  !! polygon, normals radial (outward from the slave body), and g0 within the radial gaps
  !! of the inscribed polygons widened by their sagittas.
  subroutine test_closed_loops()
    call loop_case(24, 1.0_wp, .true., 37, 1.1_wp, .false., 'pin slave in a hole')
    call loop_case(48, 1.1_wp, .false., 24, 1.0_wp, .true., 'hole slave round a pin')
  end subroutine test_closed_loops

  subroutine loop_case(ns, rs, s_inside, nm, rm, m_inside, what)
    integer, intent(in) :: ns, nm
    real(wp), intent(in) :: rs, rm
    logical, intent(in) :: s_inside, m_inside   !< the body is the disc inside the rim (else outside)
    character(len=*), intent(in) :: what
    real(wp), parameter :: pi = acos(-1.0_wp)
    real(wp), allocatable :: xs(:, :), xm(:, :)
    integer, allocatable :: es(:, :), em(:, :)
    type(mortar_t) :: mt
    real(wp) :: e_pu, e_d, e_n, glo, ghi, gbad, chord, nrm(2)
    integer :: j
    call rim(ns, rs, 0.0_wp, s_inside, 7, xs, es)
    call rim(nm, rm, 0.05_wp, m_inside, 3, xm, em)
    call build_ok(xs, es, [(.false., j = 1, ns)], xm, em, mt, what)
    call report(mt%m == ns, what//': every slave node of the loop has a row')
    chord = 2.0_wp * rs * sin(pi / ns)
    ! the radial gap at a slave node lies between the inscribed polygons' (|R cos(pi/n_m) - r|
    ! and |R - r|); the dual weights reproduce linear functions, and the gap along a slave
    ! segment departs from linear by at most the two polygons' sagittas
    glo = min(abs(rm * cos(pi / nm) - rs), abs(rm - rs)) - rs * (1.0_wp - cos(pi / ns)) - rm * (1.0_wp - cos(pi / nm))
    ghi = max(abs(rm * cos(pi / nm) - rs), abs(rm - rs)) + rs * (1.0_wp - cos(pi / ns)) + rm * (1.0_wp - cos(pi / nm))
    e_pu = 0.0_wp; e_d = 0.0_wp; e_n = 0.0_wp; gbad = 0.0_wp
    do j = 1, mt%m
      e_pu = max(e_pu, abs(slave_sum(mt, j) - 1.0_wp), abs(master_sum(mt, j) - 1.0_wp))
      e_d = max(e_d, abs(mt%d(j) - chord))
      nrm = xs(:, mt%snode(j)) / norm2(xs(:, mt%snode(j)))
      if (.not. s_inside) nrm = -nrm
      e_n = max(e_n, norm2(mt%normal(:, j) - nrm))
      gbad = max(gbad, glo - mt%g0(j), mt%g0(j) - ghi)
    end do
    call report_le(e_pu, tol, what//': partition of unity (slave and master weights sum to 1)')
    call report_le(e_d, tol, what//': D = the chord of the polygon, the loop''s first node too')
    call report_le(e_n, tol, what//': radial normals')
    call report_le(gbad, 0.0_wp, what//': g0 between the inscribed polygons'' gaps')
  end subroutine loop_case

  !> n nodes on a circle of radius r turned by phase, as one closed loop of edges listed
  !! from edge `first`; the body (inside the rim, or outside it: a hole) on the left.
  subroutine rim(n, r, phase, inside, first, x, e)
    integer, intent(in) :: n, first
    real(wp), intent(in) :: r, phase
    logical, intent(in) :: inside
    real(wp), allocatable, intent(out) :: x(:, :)
    integer, allocatable, intent(out) :: e(:, :)
    integer :: k, q, a, b
    allocate (x(2, n), e(2, n))
    do k = 1, n
      x(:, k) = r * [cos(phase + 2.0_wp * acos(-1.0_wp) * (k - 1) / n), sin(phase + 2.0_wp * acos(-1.0_wp) * (k - 1) / n)]
    end do
    do q = 1, n
      k = mod(first + q - 2, n) + 1
      a = k
      b = mod(k, n) + 1
      if (inside) then
        e(:, q) = [a, b]               ! counter-clockwise: the disc on the left
      else
        e(:, q) = [b, a]               ! clockwise: the material round the hole on the left
      end if
    end do
  end subroutine rim

  !> Each bad input gives ERR_INPUT and a message.
  !> One entry point for every dimension: mismatched coordinates and faces no mortar
  !! implements are bad input naming what was given.
  subroutine test_dispatch()
    real(wp) :: x2(2, 2), x3(3, 3)
    integer :: e2(2, 1), f3(3, 1)
    type(mortar_t) :: mt
    type(error_t) :: err
    x2 = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp], [2, 2])
    x3 = 0.0_wp
    e2(:, 1) = [1, 2]
    f3(:, 1) = [1, 2, 3]
    call mortar_build(x2, e2, [.false., .false.], x3, f3, mt, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), '2 coordinates') > 0 .and. &
                index(err%text(), 'master nodes 3') > 0, 'dispatch: slave 2D, master 3D refused ('//err%text()//')')
    call mortar_build(x3, e2, [.false., .false., .false.], x3, e2, mt, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), '3-coordinate') > 0 .and. &
                index(err%text(), 'faces of 2 (slave) and 2 (master)') > 0, &
                'dispatch: 3-coordinate nodes with 2-node faces refused ('//err%text()//')')
  end subroutine test_dispatch

  !> frame_of: column 1 the normal, orthonormal, right-handed (det = +1), in 2D the tangent
  !! (-n_y, n_x) exactly; in 3D for normals along and between the axes.
  subroutine test_frames()
    real(wp) :: f2(2, 2), f3(3, 3), n3(3), e_orth, e_det, e_n, th
    integer :: i, j
    th = 0.7_wp
    f2 = frame_of([cos(th), sin(th)])
    call report(f2(1, 2) == -sin(th) .and. f2(2, 2) == cos(th) .and. f2(1, 1) == cos(th), &
                'frames 2D: tangent (-n_y, n_x) bit for bit')
    e_orth = 0.0_wp
    e_det = 0.0_wp
    e_n = 0.0_wp
    do i = 1, 7
      select case (i)
      case (1:3)
        n3 = 0.0_wp
        n3(i) = 1.0_wp
      case (4)
        n3 = [-1.0_wp, 0.0_wp, 0.0_wp]
      case default
        n3 = [cos(i*1.3_wp), sin(i*1.3_wp)*cos(i*0.4_wp), -sin(i*1.3_wp)*sin(i*0.4_wp)]
      end select
      f3 = frame_of(n3)
      e_n = max(e_n, norm2(f3(:, 1) - n3))
      do j = 1, 3
        e_orth = max(e_orth, maxval(abs(matmul(transpose(f3), f3(:, j)) - merge(1.0_wp, 0.0_wp, [1, 2, 3] == j))))
      end do
      e_det = max(e_det, abs(f3(1, 1)*(f3(2, 2)*f3(3, 3) - f3(3, 2)*f3(2, 3)) - f3(1, 2)*(f3(2, 1)*f3(3, 3) - &
                  f3(3, 1)*f3(2, 3)) + f3(1, 3)*(f3(2, 1)*f3(3, 2) - f3(3, 1)*f3(2, 2)) - 1.0_wp))
    end do
    call report_le(e_n, tol, 'frames 3D: column 1 is the normal')
    call report_le(e_orth, tol, 'frames 3D: orthonormal')
    call report_le(e_det, tol, 'frames 3D: right-handed (det = 1)')
  end subroutine test_frames

  subroutine test_bad_input()
    real(wp) :: xs(2, 6), xm(2, 3)
    integer :: ok_em(2, 2)
    logical :: rem(6)
    xs(:, 1) = [0.0_wp, 0.0_wp]
    xs(:, 2) = [1.0_wp, 0.0_wp]
    xs(:, 3) = [2.0_wp, 0.0_wp]
    xs(:, 4) = [3.0_wp, 0.0_wp]
    xs(:, 5) = [1.0_wp, -1.0_wp]
    xs(:, 6) = [2.0_wp, 0.0_wp]             ! same place as node 3
    xm(:, 1) = [-1.0_wp, 0.1_wp]
    xm(:, 2) = [1.5_wp, 0.1_wp]
    xm(:, 3) = [4.0_wp, 0.1_wp]
    ok_em = reshape([1, 2, 2, 3], [2, 2])    ! left to right: body above, facing down
    rem = .false.
    ! The slave below, facing up: edges right to left.
    call expect_bad(xs, xm, rem, reshape([4, 3, 3, 2, 2, 1, 2, 5], [2, 4]), ok_em, 'branching slave chain', 'branch')
    call expect_bad(xs, xm, rem, reshape([2, 1, 4, 3], [2, 2]), ok_em, 'two slave chains', 'chains')
    call expect_bad(xs, xm, rem, reshape([integer ::], [2, 0]), ok_em, 'empty slave edge list', 'no slave')
    call expect_bad(xs, xm, rem, reshape([6, 3, 3, 2], [2, 2]), ok_em, 'zero-length slave edge', 'zero length')
    call expect_bad(xs, xm, rem, reshape([2, 1, 2, 3], [2, 2]), ok_em, 'inconsistent slave orientation', 'oriented')
    call expect_bad(xs, xm, rem, reshape([2, 1, 9, 2], [2, 2]), ok_em, 'slave node out of range', 'outside')
    call expect_bad(xs, xm, rem, reshape([4, 3, 3, 2, 6, 1, 1, 6], [2, 4]), ok_em, 'chain and a separate loop', 'more than one')
    call expect_bad(xs, xm, rem, reshape([3, 2, 2, 1], [2, 2]), reshape([3, 2, 2, 1], [2, 2]), 'master reversed (faces away)', &
                    'faces away')
    call expect_bad(xs, xm, rem, reshape([3, 2, 2, 1], [2, 2]), reshape([1, 2, 2, 3, 2, 1], [2, 3]), 'branching master chain', &
                    'master edges branch')
    call expect_bad(xs, xm, rem, reshape([3, 2, 2, 1], [2, 2]), ok_em, 'all slave nodes removable', 'removable', all_removable=.true.)
    call expect_bad(xs, xm, rem, reshape([3, 2, 2, 1], [2, 2]), ok_em, 'removable of the wrong size', 'entries', short_removable=.true.)
    call expect_tagged(xs, xm, rem, ok_em)
    ! master beside the slave: no overlap
    xm(1, :) = xm(1, :) + 20.0_wp
    call expect_bad(xs, xm, rem, reshape([3, 2, 2, 1], [2, 2]), ok_em, 'master beside the slave', 'does not overlap')
  end subroutine test_bad_input

  !> The node a message names is given by its tag when the caller gives tags (a mesh file's
  !! nodes are numbered for locality inside the program): a branch at node 2, tag 702.
  subroutine expect_tagged(xs, xm, rem, em_)
    real(wp), intent(in) :: xs(:, :), xm(:, :)
    logical, intent(in) :: rem(:)
    integer, intent(in) :: em_(:, :)
    type(mortar_t) :: mt
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    call mortar_build(xs, reshape([4, 3, 3, 2, 2, 1, 2, 5], [2, 4]), rem, xm, em_, mt, err, &
                      tag_s=[701, 702, 703, 704, 705, 706], tag_m=[801, 802, 803])
    call error_parts(err, info, msg)
    call report(info == ERR_INPUT .and. index(msg, 'node 702') > 0, 'bad input, branching slave chain with tags: '// &
                'the message names the tag, "'//trim(msg)//'"')
  end subroutine expect_tagged

  !> One bad input: ERR_INPUT and a message containing word.
  subroutine expect_bad(xs, xm, rem, es, em_, what, word, all_removable, short_removable)
    real(wp), intent(in) :: xs(:, :), xm(:, :)
    logical, intent(in) :: rem(6)
    integer, intent(in) :: es(:, :), em_(:, :)
    character(len=*), intent(in) :: what, word
    logical, intent(in), optional :: all_removable, short_removable
    type(mortar_t) :: mt
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    logical :: r(6)
    r = rem
    if (present(all_removable)) r = all_removable
    if (present(short_removable)) then
      call mortar_build(xs, es, r(1:5), xm, em_, mt, err)
      call error_parts(err, info, msg)
    else
      call mortar_build(xs, es, r, xm, em_, mt, err)
      call error_parts(err, info, msg)
    end if
    call report(info == ERR_INPUT .and. index(msg, word) > 0, 'bad input, '//what//': category = '//i2s(info)//', "'// &
                trim(msg)//'"')
  end subroutine expect_bad

  !> 100k slave segments (a gently curved arc) against 130k master segments (flat): the
  !! build time is reported, not asserted.
  subroutine test_timing()
    integer, parameter :: ns = 100000, nm = 130000
    real(wp), parameter :: r = 1.0e4_wp
    real(wp), allocatable :: xs(:, :), xm(:, :)
    integer, allocatable :: es(:, :), em(:, :)
    logical, allocatable :: rem(:)
    type(mortar_t) :: mt
    integer :: k, info, j
    type(error_t) :: err
    integer(8) :: t0, t1, rate
    real(wp) :: phi, e_pu
    character(len=256) :: msg
    allocate (xs(2, ns + 1), es(2, ns), xm(2, nm + 1), em(2, nm), rem(ns + 1))
    do k = 0, ns
      phi = -0.5_wp + real(k, wp) / real(ns, wp) + 0.3_wp / real(ns, wp) * hash01(k, 12)
      if (k == 0 .or. k == ns) phi = -0.5_wp + real(k, wp) / real(ns, wp)
      phi = phi * 1.0e3_wp / r                  ! arc over x in about [-500, 500]
      xs(:, k + 1) = [0.0_wp, r] + r * [sin(phi), -cos(phi)]
    end do
    do k = 1, ns
      es(:, k) = [k, k + 1]
    end do
    do k = 0, nm
      xm(:, k + 1) = [-510.0_wp + 1020.0_wp * (real(k, wp) + 0.3_wp * hash01(k, 13)) / real(nm, wp), 0.0_wp]
      if (k == 0 .or. k == nm) xm(1, k + 1) = -510.0_wp + 1020.0_wp * real(k, wp) / real(nm, wp)
    end do
    do k = 1, nm
      em(:, k) = [k + 1, k]
    end do
    rem = .false.
    call system_clock(t0, rate)
    call mortar_build(xs, es, rem, xm, em, mt, err)
    call error_parts(err, info, msg)
    call system_clock(t1)
    call report(info == 0 .and. mt%m == ns + 1, 'timing case: 100k x 130k segments built, a row per slave node')
    e_pu = 0.0_wp
    do j = 1, mt%m
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp))
    end do
    call report_le(e_pu, 1.0e-12_wp, 'timing case: partition of unity')
    write (*, '(a,f8.3,a)') 'INFO  mortar_build, 100k slave x 130k master segments: ', &
      real(t1 - t0, wp) / real(rate, wp), ' s'
  end subroutine test_timing

end program test_mortar
