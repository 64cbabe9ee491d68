!> Unit tests of the 3D surface dual mortar (module mortar_surfaces behind mortar_build),
!! every reference computed here independently of the code under test (areas by cross
!! products, tributary areas as area/3 per triangle and area/4 per parallelogram, exact
!! integrals of linear functions from the centroid, the sphere's exact normal distance):
!!  - matching flat meshes (quadrilaterals on quadrilaterals, triangles on triangles):
!!    M/D = identity (node-to-node), slave weight 1, D = tributary area, g0 = 0, normals,
!!    mortar_consistency = 0 on every row;
!!  - non-matching flat meshes, rotated and moved, master at distance h: parallelogram
!!    quadrilaterals against triangles of another size, the reverse, a mixed slave list:
!!    partition of unity, linear reproduction, g0 = h, int f for f linear, the
!!    uniform-pressure patch test on the master; trapezoids: the same to quadrature accuracy;
!!  - a slave larger than the master (turned by 10 degrees): rows exactly under the master,
!!    the patch test on the master and the force balance, sum ws = sum wm on every row;
!!  - removable nodes: no row, the patch test on both sides, sum ws = sum wm, D unchanged;
!!  - a spherical cap over a flat master: g0 against the exact normal distance, second order;
!!  - bad input, each message naming side, face or node; the build time at 100k x 130k faces.
program test_mortar_3d
  use kinds, only: wp
  use strings, only: i2s, fixed
  use mortar, only: mortar_t, mortar_build, mortar_consistency
  use testing, only: report, report_le, test_summary, error_parts
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)

  real(wp), parameter :: tol = 1.0e-12_wp
  real(wp), parameter :: pi = acos(-1.0_wp)

  !> A contact surface built here: node coordinates in the global and the local frame, faces.
  type :: surf_t
    real(wp), allocatable :: x(:, :)       !< (3, nnode) global coordinates [length]
    real(wp), allocatable :: loc(:, :)     !< (3, nnode) local coordinates (u, v, w) [length]
    integer, allocatable :: f(:, :)        !< (4, nface) faces, row 4 = 0 on a triangle
  end type surf_t

  call test_matching(4, 'matching quadrilaterals')
  call test_matching(3, 'matching triangles')
  call test_nonmatching(4, 3, 0.0_wp, 'parallelograms on triangles')
  call test_nonmatching(3, 4, 0.0_wp, 'triangles on parallelograms')
  call test_nonmatching(5, 3, 0.0_wp, 'mixed quadrilaterals and triangles on triangles')
  call test_trapezoids()
  call test_rim()
  call test_removal(4, 3, 'quadrilaterals')
  call test_removal(3, 4, 'triangles')
  call test_curved()
  call test_bad_input()
  call test_timing()

  call test_summary()

contains

  ! ---- scenes --------------------------------------------------------------------

  !> Deterministic pseudo-random number in [-0.5, 0.5) for integer pair (i, j).
  pure real(wp) function hash01(i, j)
    integer, intent(in) :: i, j                   !< the pair
    real(wp) :: v
    v = sin(12.9898_wp * real(i, wp) + 78.233_wp * real(j, wp) + 0.5_wp) * 43758.5453_wp
    hash01 = v - real(floor(v), wp) - 0.5_wp
  end function hash01

  !> n+1 positions from a to b, interior ones moved by up to +-amp of a spacing.
  function positions(n, a, b, amp, seed) result(u)
    integer, intent(in) :: n                      !< intervals
    real(wp), intent(in) :: a, b                  !< ends [length]
    real(wp), intent(in) :: amp                   !< largest move [spacings]
    integer, intent(in) :: seed                   !< seed of the moves
    real(wp) :: u(0:n)
    integer :: k
    do k = 0, n
      u(k) = a + (b - a) * real(k, wp) / real(n, wp)
      if (k > 0 .and. k < n) u(k) = u(k) + amp * (b - a) / real(n, wp) * hash01(k, seed)
    end do
  end function positions

  !> The rotation R_z(a) R_y(b) R_x(c).
  pure function rotation(a, b, c) result(q)
    real(wp), intent(in) :: a, b, c               !< angles [rad]
    real(wp) :: q(3, 3), rz(3, 3), ry(3, 3), rx(3, 3)
    rz = reshape([cos(a), sin(a), 0.0_wp, -sin(a), cos(a), 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [3, 3])
    ry = reshape([cos(b), 0.0_wp, -sin(b), 0.0_wp, 1.0_wp, 0.0_wp, sin(b), 0.0_wp, cos(b)], [3, 3])
    rx = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, cos(c), sin(c), 0.0_wp, -sin(c), cos(c)], [3, 3])
    q = matmul(rz, matmul(ry, rx))
  end function rotation

  !> A structured sheet in the local plane w = w0: node (i, j) at (uu(i) + shear vv(j), vv(j))
  !! (interior nodes moved by up to amp of the local spacing in u and v), id 1 + i + (nu+1) j;
  !! faces: shape 4 quadrilaterals, 3 triangles (each cell split, the diagonal alternating),
  !! 5 both (every third cell a quadrilateral); counter-clockwise seen from +w if up, else
  !! from -w; listed in a scrambled order. The global coordinates are off + q (u, v, w).
  function sheet(uu, vv, shear, w0, shape, up, amp, seed, q, off) result(s)
    real(wp), intent(in) :: uu(0:), vv(0:)        !< grid positions [length]
    real(wp), intent(in) :: shear                 !< u added per unit v [-]
    real(wp), intent(in) :: w0                    !< the plane's w [length]
    integer, intent(in) :: shape                  !< 4, 3 or 5
    logical, intent(in) :: up                     !< outward normal +w
    real(wp), intent(in) :: amp                   !< interior node moves [spacings]
    integer, intent(in) :: seed                   !< seed of the moves
    real(wp), intent(in) :: q(3, 3), off(3)       !< rigid motion [-], [length]
    type(surf_t) :: s
    integer :: nu, nv, i, j, k, nf, c(4), mult, e
    integer, allocatable :: f(:, :)
    real(wp) :: a, b
    nu = size(uu) - 1
    nv = size(vv) - 1
    allocate (s%x(3, (nu + 1) * (nv + 1)), s%loc(3, (nu + 1) * (nv + 1)), f(4, 2 * nu * nv))
    do j = 0, nv
      do i = 0, nu
        a = uu(i)
        b = vv(j)
        if (i > 0 .and. i < nu .and. j > 0 .and. j < nv) then
          a = a + amp * (uu(i + 1) - uu(i - 1)) / 2.0_wp * hash01(i, j + 100 * seed)
          b = b + amp * (vv(j + 1) - vv(j - 1)) / 2.0_wp * hash01(j + 7, i + 100 * seed)
        end if
        k = 1 + i + (nu + 1) * j
        s%loc(:, k) = [a + shear * b, b, w0]
      end do
    end do
    nf = 0
    do j = 0, nv - 1
      do i = 0, nu - 1
        c = [1 + i + (nu + 1) * j, 2 + i + (nu + 1) * j, 2 + i + (nu + 1) * (j + 1), 1 + i + (nu + 1) * (j + 1)]
        if (shape == 4 .or. (shape == 5 .and. mod(i + 2 * j, 3) == 0)) then
          nf = nf + 1
          f(:, nf) = c
        else if (mod(i + j, 2) == 0) then
          f(:, nf + 1) = [c(1), c(2), c(3), 0]
          f(:, nf + 2) = [c(1), c(3), c(4), 0]
          nf = nf + 2
        else
          f(:, nf + 1) = [c(1), c(2), c(4), 0]
          f(:, nf + 2) = [c(2), c(3), c(4), 0]
          nf = nf + 2
        end if
      end do
    end do
    if (.not. up) then
      do k = 1, nf
        if (f(4, k) == 0) then
          f(:, k) = [f(1, k), f(3, k), f(2, k), 0]
        else
          f(:, k) = [f(1, k), f(4, k), f(3, k), f(2, k)]
        end if
      end do
    end if
    mult = 7                                       ! a multiplier prime to nf scrambles the order
    do while (gcd(mult, nf) /= 1)
      mult = mult + 2
    end do
    allocate (s%f(4, nf))
    do k = 1, nf
      e = 1 + mod(mult * (k - 1), nf)
      s%f(:, e) = f(:, k)
    end do
    call place(s, q, off)
  end function sheet

  !> Greatest common divisor.
  pure integer function gcd(a, b)
    integer, intent(in) :: a, b                   !< the numbers
    integer :: x, y, t
    x = a
    y = b
    do while (y /= 0)
      t = mod(x, y)
      x = y
      y = t
    end do
    gcd = x
  end function gcd

  !> Global coordinates from the local ones: off + q loc.
  subroutine place(s, q, off)
    type(surf_t), intent(inout) :: s              !< the surface
    real(wp), intent(in) :: q(3, 3), off(3)       !< rigid motion [-], [length]
    integer :: k
    if (allocated(s%x)) deallocate (s%x)
    allocate (s%x(3, size(s%loc, 2)))
    do k = 1, size(s%loc, 2)
      s%x(:, k) = off + matmul(q, s%loc(:, k))
    end do
  end subroutine place

  !> Renumber a surface's nodes: node k becomes perm(k).
  subroutine renumber(s, perm)
    type(surf_t), intent(inout) :: s              !< the surface
    integer, intent(in) :: perm(:)                !< new id of each node
    integer :: k, a
    s%x(:, perm) = s%x
    s%loc(:, perm) = s%loc
    do k = 1, size(s%f, 2)
      do a = 1, 4
        if (s%f(a, k) > 0) s%f(a, k) = perm(s%f(a, k))
      end do
    end do
  end subroutine renumber

  !> Area of face k (a triangle, or a planar quadrilateral by its diagonals).
  pure real(wp) function face_area(x, f, k)
    real(wp), intent(in) :: x(:, :)               !< node coordinates [length]
    integer, intent(in) :: f(:, :), k             !< faces, the face
    if (f(4, k) == 0) then
      face_area = 0.5_wp * norm2(cross(x(:, f(2, k)) - x(:, f(1, k)), x(:, f(3, k)) - x(:, f(1, k))))
    else
      face_area = 0.5_wp * norm2(cross(x(:, f(3, k)) - x(:, f(1, k)), x(:, f(4, k)) - x(:, f(2, k))))
    end if
  end function face_area

  !> Tributary areas int N_k: area/3 per triangle, area/4 per parallelogram.
  function tributary(s) result(t)
    type(surf_t), intent(in) :: s                 !< the surface (quadrilaterals parallelograms)
    real(wp) :: t(size(s%x, 2))
    integer :: k, nv
    t = 0.0_wp
    do k = 1, size(s%f, 2)
      nv = merge(3, 4, s%f(4, k) == 0)
      t(s%f(1:nv, k)) = t(s%f(1:nv, k)) + face_area(s%x, s%f, k) / real(nv, wp)
    end do
  end function tributary

  !> Cross product in 3D.
  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)            !< the vectors
    real(wp) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross

  !> Sum of row j's slave weights.
  real(wp) function slave_sum(mt, j)
    type(mortar_t), intent(in) :: mt              !< the rows
    integer, intent(in) :: j                      !< the row
    slave_sum = sum(mt%sval(mt%sptr(j):mt%sptr(j + 1) - 1))
  end function slave_sum

  !> Sum of row j's master weights.
  real(wp) function master_sum(mt, j)
    type(mortar_t), intent(in) :: mt              !< the rows
    integer, intent(in) :: j                      !< the row
    master_sum = sum(mt%mval(mt%mptr(j):mt%mptr(j + 1) - 1))
  end function master_sum

  !> sum_l w_jl x_l of row j of one side's weights in compressed rows.
  function row_point(ptr, nod, val, j, x) result(p)
    integer, intent(in) :: ptr(:), nod(:), j      !< row pointers, node ids, the row
    real(wp), intent(in) :: val(:), x(:, :)       !< weights [-], node coordinates [length]
    real(wp) :: p(3)
    integer :: e
    p = 0.0_wp
    do e = ptr(j), ptr(j + 1) - 1
      p = p + val(e) * x(:, nod(e))
    end do
  end function row_point

  !> Nodal forces of multipliers lam on one side: f_l = sum_j lam_j w_jl.
  function side_forces(ptr, nod, val, lam, nnode) result(f)
    integer, intent(in) :: ptr(:), nod(:)         !< row pointers, node ids
    real(wp), intent(in) :: val(:), lam(:)        !< weights [-], multipliers [force]
    integer, intent(in) :: nnode                  !< nodes of the side
    real(wp) :: f(nnode)
    integer :: j, e
    f = 0.0_wp
    do j = 1, size(lam)
      do e = ptr(j), ptr(j + 1) - 1
        f(nod(e)) = f(nod(e)) + lam(j) * val(e)
      end do
    end do
  end function side_forces

  !> Build through the entry point (triangle-only lists as 3-row arrays) and stop the test
  !! program if it fails.
  subroutine build_ok(s, removable, m, mt, what)
    type(surf_t), intent(in) :: s, m              !< slave, master
    logical, intent(in) :: removable(:)           !< removable slave nodes
    type(mortar_t), intent(out) :: mt             !< the rows
    character(len=*), intent(in) :: what          !< the case
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    if (all(s%f(4, :) == 0) .and. all(m%f(4, :) == 0)) then
      call mortar_build(s%x, s%f(1:3, :), removable, m%x, m%f(1:3, :), mt, err)
    else if (all(s%f(4, :) == 0)) then
      call mortar_build(s%x, s%f(1:3, :), removable, m%x, m%f, mt, err)
    else
      call mortar_build(s%x, s%f, removable, m%x, m%f, mt, err)
    end if
    call error_parts(err, info, msg)
    call report(info == 0 .and. msg == '', what//': mortar_build succeeds')
    if (info /= 0) then
      write (*, '(a)') 'FAIL  '//what//': '//trim(msg)
      call test_summary()
      error stop 1
    end if
  end subroutine build_ok

  ! ---- checks ----------------------------------------------------------------------

  !> Matching flat meshes, rotated and moved: the master the same nodes renumbered in
  !! reverse, its faces reversed. M/D = identity, slave weight 1, D = tributary area,
  !! g0 = 0, normals, consistency 0 on every row.
  subroutine test_matching(shape, what)
    integer, intent(in) :: shape                  !< 4 or 3
    character(len=*), intent(in) :: what          !< the case
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: q(3, 3), off(3), t(5 * 4), e_m, e_s, e_d, e_g, e_n, dev, wv
    integer :: j, k, e, nn, nbad, nfull
    integer, allocatable :: perm(:)
    q = rotation(0.3_wp, -0.5_wp, 0.8_wp)
    off = [1.0_wp, -2.0_wp, 0.5_wp]
    s = sheet(positions(4, 0.0_wp, 1.0_wp, 0.6_wp, 1), positions(3, 0.0_wp, 0.8_wp, 0.6_wp, 2), 0.25_wp, 0.0_wp, &
              shape, .true., 0.0_wp, 1, q, off)
    m = sheet(positions(4, 0.0_wp, 1.0_wp, 0.6_wp, 1), positions(3, 0.0_wp, 0.8_wp, 0.6_wp, 2), 0.25_wp, 0.0_wp, &
              shape, .false., 0.0_wp, 1, q, off)
    nn = size(s%x, 2)
    perm = [(nn + 1 - k, k = 1, nn)]             ! master node of slave node k
    call renumber(m, perm)
    call build_ok(s, [(.false., k = 1, nn)], m, mt, what)
    call report(mt%m == nn, what//': one row per slave node')
    t(1:nn) = tributary(s)
    e_m = 0.0_wp; e_s = 0.0_wp; e_d = 0.0_wp; e_g = 0.0_wp; e_n = 0.0_wp
    nbad = 0
    do j = 1, mt%m
      k = mt%snode(j)
      if (k /= j) nbad = nbad + 1000
      e_s = max(e_s, abs(slave_sum(mt, j) - 1.0_wp))
      if (mt%sptr(j + 1) - mt%sptr(j) /= 1 .or. mt%snod(mt%sptr(j)) /= k) nbad = nbad + 1
      if (.not. any(mt%mnod(mt%mptr(j):mt%mptr(j + 1) - 1) == perm(k))) nbad = nbad + 1
      do e = mt%mptr(j), mt%mptr(j + 1) - 1
        wv = mt%mval(e)
        e_m = max(e_m, abs(wv - merge(1.0_wp, 0.0_wp, mt%mnod(e) == perm(k))))
      end do
      e_d = max(e_d, abs(mt%d(j) - t(k)))
      e_g = max(e_g, abs(mt%g0(j)))
      e_n = max(e_n, norm2(mt%normal(:, j) - q(:, 3)))
    end do
    call report(nbad == 0, what//': rows by slave node, own slave node only, its matching master node present')
    call report_le(e_m, tol, what//': M/D = identity')
    call report_le(e_s, tol, what//': slave weight 1')
    call report_le(e_d, tol, what//': D = tributary area')
    call report_le(e_g, tol, what//': g0 = 0')
    call report_le(e_n, tol, what//': normals = the plane''s')
    call mortar_consistency(mt, dev, nfull)
    call report(nfull == nn, what//': consistency measured on every row (all fully covered)')
    call report_le(dev, tol, what//': max |sum_l M_jl - D_jj| / D_jj = 0')
  end subroutine test_matching

  !> Slave and master on the same parallelogram domain (u in [0, 1] sheared by 0.3, v in
  !! [0, 1]), grids of different sizes and spacings, slave faces of shape ss, master of
  !! shape sm (quadrilaterals parallelograms), the master at distance h, the scene rotated
  !! and moved. Every row fully covered.
  subroutine test_nonmatching(ss, sm, amp, what)
    integer, intent(in) :: ss, sm                 !< face shapes (4, 3, 5)
    real(wp), intent(in) :: amp                   !< slave interior node moves (0: parallelograms)
    character(len=*), intent(in) :: what          !< the case
    real(wp), parameter :: h = 0.04_wp, shear = 0.3_wp, p = 7.0_wp
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: q(3, 3), off(3), e_pu, e_ws, e_lin, e_lin2, e_g, e_n, e_d, integral, exact, loc(3), dev
    real(wp), allocatable :: ts(:), tm(:), fm(:)
    integer :: j, k, e, nfull
    q = rotation(1.1_wp, 0.7_wp, -0.4_wp)
    off = [3.0_wp, -2.0_wp, 1.5_wp]
    s = sheet(positions(6, 0.0_wp, 1.0_wp, 0.6_wp, 3), positions(5, 0.0_wp, 1.0_wp, 0.6_wp, 4), shear, 0.0_wp, &
              ss, .true., amp, 5, q, off)
    m = sheet(positions(4, 0.0_wp, 1.0_wp, 0.6_wp, 6), positions(5, 0.0_wp, 1.0_wp, 0.6_wp, 7), shear, h, &
              sm, .false., 0.0_wp, 8, q, off)
    call build_ok(s, [(.false., k = 1, size(s%x, 2))], m, mt, what)
    call report(mt%m == size(s%x, 2), what//': one row per slave node')
    ts = tributary(s)
    tm = tributary(m)
    e_pu = 0.0_wp; e_ws = 0.0_wp; e_lin = 0.0_wp; e_lin2 = 0.0_wp; e_g = 0.0_wp; e_n = 0.0_wp; e_d = 0.0_wp
    integral = 0.0_wp
    do j = 1, mt%m
      k = mt%snode(j)
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp))
      e_ws = max(e_ws, abs(slave_sum(mt, j) - 1.0_wp))
      e_lin = max(e_lin, norm2(row_point(mt%mptr, mt%mnod, mt%mval, j, m%x) - s%x(:, k) - h * q(:, 3)))
      ! the same about the slave node (independent of where the origin is)
      e_lin2 = max(e_lin2, norm2(row_point(mt%mptr, mt%mnod, mt%mval, j, m%x - spread(s%x(:, k), 2, size(m%x, 2))) - &
                                 h * q(:, 3)))
      e_g = max(e_g, abs(mt%g0(j) - h))
      e_n = max(e_n, norm2(mt%normal(:, j) - q(:, 3)))
      e_d = max(e_d, abs(mt%d(j) - ts(k)))
      ! int f over the slave, f = 2 + 3 u + 5 v in the local frame, through the master nodes
      do e = mt%mptr(j), mt%mptr(j + 1) - 1
        loc = matmul(transpose(q), m%x(:, mt%mnod(e)) - off)
        integral = integral + mt%d(j) * mt%mval(e) * (2.0_wp + 3.0_wp * loc(1) + 5.0_wp * loc(2))
      end do
    end do
    ! the domain: area 1, centroid (0.5 + 0.5 shear, 0.5)
    exact = 2.0_wp + 3.0_wp * (0.5_wp + 0.5_wp * shear) + 5.0_wp * 0.5_wp
    call mortar_consistency(mt, dev, nfull)
    fm = side_forces(mt%mptr, mt%mnod, mt%mval, p * mt%d, size(m%x, 2))
    if (amp == 0.0_wp) then
      call report_le(e_pu, tol, what//': partition of unity sum_l M_jl/D_jj = 1')
      call report_le(e_ws, tol, what//': slave weight 1')
      call report_le(e_lin, tol, what//': sum_l (M_jl/D_jj) x^m_l = x^s_j + h n_j')
      call report_le(e_g, tol, what//': g0 = h on every row')
      call report_le(abs(integral - exact), tol, what//': sum_j D_jj sum_l (M_jl/D_jj) f(x^m_l) = int f for f linear')
      call report_le(e_n, tol, what//': normals')
      call report_le(e_d, tol, what//': D = slave tributary area')
      call report(nfull == mt%m, what//': consistency measured on every row')
      call report_le(dev, tol, what//': max |sum_l M_jl - D_jj| / D_jj = 0 (flat, exact rule)')
      call report_le(maxval(abs(fm - p * tm)) / p, tol, what//': uniform pressure reaches the master exactly (patch test)')
    else
      ! Trapezoids: Phi_j (xi(y)) is not polynomial in the plane, the 7-point rule is not
      ! exact; measured 4e-5 on these cells (interior nodes moved by up to 0.35 x 0.5 of the
      ! spacing). Bound 1e-4.
      call report_le(e_ws, tol, what//': slave weight 1 (D_e and the own weight from the same rule)')
      call report_le(dev, 1.0e-4_wp, what//': diagnostic max |sum_l M_jl - D_jj| / D_jj (quadrature accuracy, bound 1e-4)')
      call report_le(e_pu, 1.0e-4_wp, what//': partition of unity to quadrature accuracy (bound 1e-4)')
      ! the duals still sum to 1 exactly (the rows of D_e M_e^-1 sum to 1 whatever the rule,
      ! as D_e 1 = M_e 1), and the rule integrates the master triangles' N^m_l exactly
      call report_le(maxval(abs(fm - p * tm)) / p, tol, what//': uniform pressure still reaches the master exactly '// &
                     '(the duals sum to 1)')
      call report_le(e_g / h, 1.0e-4_wp, what//': g0 = h to quadrature accuracy (relative, bound 1e-4)')
      call report_le(e_lin2, 2.0e-5_wp, what//': |sum_l (M_jl/D_jj) (x^m_l - x^s_j) - h n_j| to quadrature '// &
                     'accuracy (bound 1e-4 of the cell size 0.2)')
    end if
  end subroutine test_nonmatching

  !> Non-parallelogram slave quadrilaterals (interior nodes moved by up to a third of the
  !! spacing): the identities hold to quadrature accuracy only (METHOD-3D 2.3).
  subroutine test_trapezoids()
    call test_nonmatching(4, 3, 0.35_wp, 'trapezoids on triangles')
  end subroutine test_trapezoids

  !> Slave (parallelogram quadrilaterals, sheared by 0.2, u in [0, 1.4], v in [0, 1.2])
  !! larger than the master (triangles on a 0.8 x 0.7 rectangle turned by 10 degrees in
  !! the plane, inside the slave), at distance h. Rows exactly at the slave nodes over the
  !! master; the patch test on the master exact; the slave's total force p times the
  !! master's area; sum ws = sum wm and g0 = h sum ws on every row.
  subroutine test_rim()
    real(wp), parameter :: h = 0.03_wp, p = 5.0_wp, ang = 10.0_wp * pi / 180.0_wp, c0(2) = [0.45_wp, 0.22_wp]
    real(wp), parameter :: la = 0.8_wp, lb = 0.7_wp
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: q(3, 3), off(3), r2(2, 2), ab(2), e_inv, e_g, e_pu, dmin
    real(wp), allocatable :: tm(:), fm(:), fs(:)
    logical, allocatable :: under(:), hasrow(:)
    integer :: j, k, nfull
    q = rotation(-0.6_wp, 0.3_wp, 1.2_wp)
    off = [-1.0_wp, 0.5_wp, 2.0_wp]
    s = sheet(positions(9, 0.0_wp, 1.4_wp, 0.5_wp, 11), positions(8, 0.0_wp, 1.2_wp, 0.5_wp, 12), 0.2_wp, 0.0_wp, &
              4, .true., 0.0_wp, 13, q, off)
    m = sheet(positions(5, 0.0_wp, la, 0.5_wp, 14), positions(6, 0.0_wp, lb, 0.5_wp, 15), 0.0_wp, h, &
              3, .false., 0.0_wp, 16, q, off)
    ! turn the master by ang about w and move it to c0 (local frame), then place it again
    r2 = reshape([cos(ang), sin(ang), -sin(ang), cos(ang)], [2, 2])
    do k = 1, size(m%loc, 2)
      m%loc(1:2, k) = c0 + matmul(r2, m%loc(1:2, k))
    end do
    call place(m, q, off)
    call build_ok(s, [(.false., k = 1, size(s%x, 2))], m, mt, 'rim')
    ! the slave nodes over the master, by their coordinates in the master's frame
    allocate (under(size(s%x, 2)), hasrow(size(s%x, 2)))
    dmin = huge(1.0_wp)
    do k = 1, size(s%x, 2)
      ab = matmul(transpose(r2), s%loc(1:2, k) - c0)
      under(k) = ab(1) > 0.0_wp .and. ab(1) < la .and. ab(2) > 0.0_wp .and. ab(2) < lb
      dmin = min(dmin, abs(ab(1)), abs(ab(1) - la), abs(ab(2)), abs(ab(2) - lb))
    end do
    hasrow = .false.
    hasrow(mt%snode) = .true.
    call report(all(hasrow .eqv. under), 'rim: rows exactly at the '//i2s(count(under))//' slave nodes over the master '// &
                '(got '//i2s(mt%m)//'; the nearest node '//fixed(dmin, '(f0.3)')//' from the master''s edge)')
    e_inv = 0.0_wp; e_g = 0.0_wp
    do j = 1, mt%m
      e_inv = max(e_inv, abs(slave_sum(mt, j) - master_sum(mt, j)))
      e_g = max(e_g, abs(mt%g0(j) - h * slave_sum(mt, j)))
    end do
    call report_le(e_inv, tol, 'rim: sum of slave weights = sum of master weights on every row')
    call report_le(e_g, tol, 'rim: g0 = h * (sum of weights) on every row')
    call mortar_consistency(mt, e_pu, nfull)
    call report(nfull > 0 .and. nfull < mt%m, 'rim: '//i2s(nfull)//' interior rows fully covered and unmodified, '// &
                i2s(mt%m - nfull)//' rim rows modified')
    call report_le(e_pu, tol, 'rim: partition of unity on the interior rows')
    tm = tributary(m)
    fm = side_forces(mt%mptr, mt%mnod, mt%mval, p * mt%d, size(m%x, 2))
    fs = side_forces(mt%sptr, mt%snod, mt%sval, p * mt%d, size(s%x, 2))
    call report_le(maxval(abs(fm - p * tm)) / p, tol, 'rim: uniform pressure reaches every master node exactly (patch test)')
    call report_le(abs(sum(fs) - p * la * lb) / p, tol, 'rim: the slave''s forces sum to p times the master''s area')
  end subroutine test_rim

  !> Removable slave nodes (an interior node, two adjacent interior ones, a corner, a whole
  !! side), slave and master non-matching on the same domain at distance h: no row at a
  !! removed node, D unchanged, sum ws = sum wm, g0 = h sum ws, and the patch test on both
  !! sides, the removed nodes' share included.
  subroutine test_removal(ss, sm, what)
    integer, intent(in) :: ss, sm                 !< face shapes
    character(len=*), intent(in) :: what          !< the case
    real(wp), parameter :: h = 0.02_wp, p = 3.0_wp
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: q(3, 3), off(3), e_inv, e_g, e_d
    real(wp), allocatable :: ts(:), tm(:), fm(:), fs(:)
    logical, allocatable :: rem(:)
    integer :: j, k, nn, case_, nu
    character(len=:), allocatable :: lab
    q = rotation(2.0_wp, -1.0_wp, 0.3_wp)
    off = [0.0_wp, 4.0_wp, -1.0_wp]
    nu = 6
    s = sheet(positions(nu, 0.0_wp, 1.0_wp, 0.5_wp, 21), positions(5, 0.0_wp, 1.0_wp, 0.5_wp, 22), -0.2_wp, 0.0_wp, &
              ss, .true., 0.0_wp, 23, q, off)
    m = sheet(positions(4, 0.0_wp, 1.0_wp, 0.5_wp, 24), positions(3, 0.0_wp, 1.0_wp, 0.5_wp, 25), -0.2_wp, h, &
              sm, .false., 0.0_wp, 26, q, off)
    nn = size(s%x, 2)
    ts = tributary(s)
    tm = tributary(m)
    allocate (rem(nn))
    do case_ = 1, 4
      rem = .false.
      select case (case_)
      case (1)
        rem(1 + 2 + (nu + 1) * 2) = .true.
        lab = what//', an interior node removed'
      case (2)
        rem(1 + 3 + (nu + 1) * 2) = .true.
        rem(1 + 3 + (nu + 1) * 3) = .true.
        lab = what//', two adjacent interior nodes removed'
      case (3)
        rem(1) = .true.
        lab = what//', a corner removed'
      case (4)
        rem(1:nu + 1) = .true.
        lab = what//', the side v = 0 removed'
      end select
      call build_ok(s, rem, m, mt, lab)
      call report(mt%m == nn - count(rem) .and. .not. any(rem(mt%snode)), lab//': a row at every other node')
      e_inv = 0.0_wp; e_g = 0.0_wp; e_d = 0.0_wp
      do j = 1, mt%m
        k = mt%snode(j)
        e_inv = max(e_inv, abs(slave_sum(mt, j) - master_sum(mt, j)))
        e_g = max(e_g, abs(mt%g0(j) - h * slave_sum(mt, j)))
        e_d = max(e_d, abs(mt%d(j) - ts(k)))
      end do
      call report_le(e_inv, tol, lab//': sum of slave weights = sum of master weights')
      call report_le(e_g, tol, lab//': g0 = h * (sum of weights)')
      call report_le(e_d, tol, lab//': D_jj unchanged (int N_j)')
      fm = side_forces(mt%mptr, mt%mnod, mt%mval, p * mt%d, size(m%x, 2))
      fs = side_forces(mt%sptr, mt%snod, mt%sval, p * mt%d, nn)
      call report_le(maxval(abs(fm - p * tm)) / p, tol, lab//': uniform pressure reaches the master exactly (patch test)')
      call report_le(maxval(abs(fs - p * ts)) / p, tol, lab//': and the slave, the removed nodes'' share included')
    end do
  end subroutine test_removal

  !> A spherical cap (radius R = 1, centre (0, 0, R), the ball above) over the flat master
  !! z = 0 touching it at the origin; n x n bilinear (warped) quadrilaterals on a smoothly
  !! graded grid over [-0.3, 0.3]^2, projected vertically onto the sphere. g0_j / (slave
  !! weight sum) against the exact distance from x_j along the sphere's normal to the
  !! plane, R z/(R - z), at the interior nodes: second order over 3 meshes.
  subroutine test_curved()
    real(wp) :: err(3), erim(3), e_pu(3), hmax(3), rate1, rate2
    integer :: lev
    do lev = 1, 3
      call cap_case(8 * 2**(lev - 1), err(lev), erim(lev), e_pu(lev), hmax(lev))
      ! warped faces: D_jj by 3x3 Gauss, M by the 7-point rule with the surface/plane ratio
      ! (not polynomial): equal to quadrature accuracy, measured 1e-13 at n = 8
      call report_le(e_pu(lev), 1.0e-11_wp, 'curved n = '//i2s(8 * 2**(lev - 1))// &
                     ': partition of unity, slave weight 1 (master covers the cap; warped faces, bound 1e-11)')
      write (*, '(a,i0,a,es10.3,a,es10.3,a,es10.3)') 'INFO  curved n = ', 8 * 2**(lev - 1), ': h = ', hmax(lev), &
        ', max |g0/sw - exact normal distance| interior ', err(lev), ', rim ', erim(lev)
    end do
    rate1 = log(err(1) / err(2)) / log(hmax(1) / hmax(2))
    rate2 = log(err(2) / err(3)) / log(hmax(2) / hmax(3))
    call report(rate1 > 1.7_wp .and. rate2 > 1.7_wp, 'curved: g0 error at the interior nodes falls at second order '// &
                '(observed orders '//fixed(rate1, '(f0.3)')//', '//fixed(rate2, '(f0.3)')//' > 1.7)')
    call report_le(err(3), hmax(3)**2, 'curved n = 32: max |g0/sw - exact normal distance| <= h^2/R')
  end subroutine test_curved

  !> One cap mesh: the error at interior and rim nodes, the partition of unity, the longest edge.
  subroutine cap_case(n, emax, erim, e_pu, hm)
    integer, intent(in) :: n                      !< cells per direction
    real(wp), intent(out) :: emax, erim, e_pu, hm !< errors [length], [-]; longest edge [length]
    real(wp), parameter :: r = 1.0_wp, a = 0.3_wp
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: uu(0:n), t, z, dist, eye(3, 3)
    integer :: i, j, k, nu
    logical :: rim
    eye = rotation(0.0_wp, 0.0_wp, 0.0_wp)
    do i = 0, n
      t = -1.0_wp + 2.0_wp * real(i, wp) / real(n, wp)
      uu(i) = a * (t + 0.12_wp * sin(pi * t))
    end do
    s = sheet(uu, uu, 0.0_wp, 0.0_wp, 4, .false., 0.0_wp, 1, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    do k = 1, size(s%loc, 2)
      s%loc(3, k) = r - sqrt(r**2 - s%loc(1, k)**2 - s%loc(2, k)**2)
    end do
    call place(s, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    m = sheet(positions(7, -0.5_wp, 0.5_wp, 0.4_wp, 31), positions(6, -0.5_wp, 0.5_wp, 0.4_wp, 32), 0.0_wp, 0.0_wp, &
              3, .true., 0.0_wp, 33, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    call build_ok(s, [(.false., k = 1, size(s%x, 2))], m, mt, 'curved n = '//i2s(n))
    call report(mt%m == size(s%x, 2), 'curved n = '//i2s(n)//': every slave node has a row')
    hm = 0.0_wp
    do k = 1, size(s%f, 2)
      do i = 1, 4
        hm = max(hm, norm2(s%x(:, s%f(mod(i, 4) + 1, k)) - s%x(:, s%f(i, k))))
      end do
    end do
    nu = n
    emax = 0.0_wp; erim = 0.0_wp; e_pu = 0.0_wp
    do j = 1, mt%m
      k = mt%snode(j)
      z = s%x(3, k)
      dist = r * z / (r - z)
      i = mod(k - 1, nu + 1)
      rim = i == 0 .or. i == nu .or. (k - 1) / (nu + 1) == 0 .or. (k - 1) / (nu + 1) == nu
      if (rim) then
        erim = max(erim, abs(mt%g0(j) / slave_sum(mt, j) - dist))
      else
        emax = max(emax, abs(mt%g0(j) / slave_sum(mt, j) - dist))
      end if
      e_pu = max(e_pu, abs(master_sum(mt, j) - 1.0_wp), abs(slave_sum(mt, j) - 1.0_wp))
    end do
  end subroutine cap_case

  !> Each bad input gives ERR_INPUT and a message naming what it should.
  subroutine test_bad_input()
    type(surf_t) :: s, m
    real(wp) :: eye(3, 3)
    integer, allocatable :: fs(:, :), fm(:, :), tags(:)
    logical, allocatable :: rem(:)
    real(wp), allocatable :: xs(:, :)
    integer :: k
    eye = rotation(0.0_wp, 0.0_wp, 0.0_wp)
    s = sheet(positions(2, 0.0_wp, 1.0_wp, 0.0_wp, 1), positions(2, 0.0_wp, 1.0_wp, 0.0_wp, 1), 0.0_wp, 0.0_wp, &
              4, .true., 0.0_wp, 1, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    m = sheet(positions(3, -0.1_wp, 1.1_wp, 0.0_wp, 1), positions(3, -0.1_wp, 1.1_wp, 0.0_wp, 1), 0.0_wp, 0.05_wp, &
              3, .false., 0.0_wp, 1, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    allocate (rem(size(s%x, 2)))
    rem = .false.
    tags = [(700 + k, k = 1, size(s%x, 2))]
    ! a node id out of range (slave face 2, master face 3)
    fs = s%f
    fs(3, 2) = 99
    call expect_bad(s%x, fs, rem, m%x, m%f, 'slave node out of range', ['slave face 2', '99          '])
    fm = m%f
    fm(1, 3) = 0
    call expect_bad(s%x, s%f, rem, m%x, fm, 'master node 0', ['master face 3', 'outside      '])
    ! a degenerate slave face: three collinear nodes (tags named)
    fs = s%f
    fs(:, 1) = [1, 2, 3, 0]
    call expect_bad(s%x, fs, rem, m%x, m%f, 'collinear slave triangle', ['slave face 1', 'zero area   ', '701 702 703 '], tags)
    fs = s%f
    fs(:, 4) = [fs(1, 4), fs(2, 4), fs(2, 4), fs(4, 4)]
    call expect_bad(s%x, fs, rem, m%x, m%f, 'slave face repeating a node', &
                    ['slave face 4', 'repeats node', i2s(700 + fs(2, 4)) // '         '], tags)
    fm = m%f
    fm(2, 5) = fm(1, 5)
    call expect_bad(s%x, s%f, rem, m%x, fm, 'master face repeating a node', ['master face 5', 'repeats node '])
    ! a slave quadrilateral that is not convex: the centre node (5) pulled towards node 1,
    ! a reflex corner of face (1, 2, 5, 4)
    xs = s%x
    xs(:, 5) = [0.15_wp, 0.15_wp, 0.0_wp]
    call expect_bad(xs, s%f, rem, m%x, m%f, 'non-convex slave quadrilateral', &
                    ['slave face            ', 'not convex at node 705'], tags)
    call expect_bad(s%x, s%f(:, 1:0), rem, m%x, m%f, 'no slave faces', ['no slave faces'])
    call expect_bad(s%x, s%f, rem, m%x, m%f(:, 1:0), 'no master faces', ['no master faces'])
    ! the master's faces reversed: they face away
    fm = m%f
    fm(2:3, :) = m%f(3:2:-1, :)
    call expect_bad(s%x, s%f, rem, m%x, fm, 'master faces facing away', ['faces away'])
    ! the slave folded: a second copy of a face, reversed
    fs = reshape([s%f(:, 1), s%f(1, 1), s%f(4, 1), s%f(3, 1), s%f(2, 1)], [4, 2])
    call expect_bad(s%x, fs, rem, m%x, m%f, 'slave folded onto itself', ['folds back'])
    ! the master beside the slave
    xs = m%x
    xs(1, :) = xs(1, :) + 5.0_wp
    call expect_bad(s%x, s%f, rem, xs, m%f, 'master beside the slave', ['does not overlap'])
    rem = .true.
    call expect_bad(s%x, s%f, rem, m%x, m%f, 'all slave nodes removable', ['removable'])
    call expect_bad(s%x, s%f, rem(1:3), m%x, m%f, 'removable of the wrong size', ['entries'])
    rem = .false.
    call expect_bad(s%x, s%f, rem, m%x, m%f, 'axisymmetric with 3-coordinate nodes', ['axisymmetric'], axisym=.true.)
  end subroutine test_bad_input

  !> One bad input: ERR_INPUT and a message containing every word.
  subroutine expect_bad(xs, fs, rem, xm, fm, what, words, tag_s, axisym)
    real(wp), intent(in) :: xs(:, :), xm(:, :)    !< slave and master node coordinates [length]
    integer, intent(in) :: fs(:, :), fm(:, :)     !< slave and master faces
    logical, intent(in) :: rem(:)                 !< removable slave nodes
    character(len=*), intent(in) :: what, words(:)  !< the case, the words the message must hold
    integer, intent(in), optional :: tag_s(:)     !< slave node tags
    logical, intent(in), optional :: axisym       !< passed as axisymmetric
    type(mortar_t) :: mt
    integer :: info, k
    type(error_t) :: err
    character(len=512) :: msg
    logical :: ok
    call mortar_build(xs, fs, rem, xm, fm, mt, err, tag_s=tag_s, axisymmetric=axisym)
    call error_parts(err, info, msg)
    ok = info == ERR_INPUT
    do k = 1, size(words)
      ok = ok .and. index(msg, trim(words(k))) > 0
    end do
    call report(ok, 'bad input, '//what//': category = '//i2s(info)//', "'//trim(msg)//'"')
  end subroutine expect_bad

  !> 316 x 316 slave quadrilaterals (a gently curved cylinder of radius 1e4) against
  !! 255 x 255 x 2 master triangles (flat, slightly larger): the build time is reported,
  !! not asserted.
  subroutine test_timing()
    type(surf_t) :: s, m
    type(mortar_t) :: mt
    real(wp) :: eye(3, 3), e_pu, dev
    integer :: k, info, nfull
    type(error_t) :: err
    character(len=256) :: msg
    integer(8) :: t0, t1, rate
    eye = rotation(0.0_wp, 0.0_wp, 0.0_wp)
    s = sheet(positions(316, 0.0_wp, 100.0_wp, 0.3_wp, 41), positions(316, 0.0_wp, 100.0_wp, 0.3_wp, 42), 0.0_wp, &
              0.0_wp, 4, .false., 0.0_wp, 43, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    do k = 1, size(s%loc, 2)
      s%loc(3, k) = 0.01_wp + 1.0e4_wp - sqrt(1.0e8_wp - (s%loc(1, k) - 50.0_wp)**2)
    end do
    call place(s, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    m = sheet(positions(255, -2.0_wp, 102.0_wp, 0.3_wp, 44), positions(255, -2.0_wp, 102.0_wp, 0.3_wp, 45), 0.0_wp, &
              0.0_wp, 3, .true., 0.0_wp, 46, eye, [0.0_wp, 0.0_wp, 0.0_wp])
    call system_clock(t0, rate)
    call mortar_build(s%x, s%f, [(.false., k = 1, size(s%x, 2))], m%x, m%f(1:3, :), mt, err)
    call system_clock(t1)
    call error_parts(err, info, msg)
    call report(info == 0 .and. mt%m == size(s%x, 2), 'timing case: '//i2s(size(s%f, 2))//' slave quadrilaterals x '// &
                i2s(size(m%f, 2))//' master triangles built, a row per slave node')
    e_pu = 0.0_wp
    do k = 1, mt%m
      e_pu = max(e_pu, abs(master_sum(mt, k) - 1.0_wp))
    end do
    call mortar_consistency(mt, dev, nfull)
    call report_le(e_pu, 1.0e-10_wp, 'timing case: partition of unity (warped faces, quadrature accuracy)')
    write (*, '(a,f8.3,a)') 'INFO  mortar_build, 100k slave quadrilaterals x 130k master triangles: ', &
      real(t1 - t0, wp) / real(rate, wp), ' s'
  end subroutine test_timing

end program test_mortar_3d
