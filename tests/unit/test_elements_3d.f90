!> Unit tests of the 3D element kernels (module elements_3d), every reference computed here
!! independently of the code under test:
!!  - the shape functions: a partition of unity, gradients summing to 0 and reproducing a
!!    linear field (sum_a x_a g_a' = I) on a distorted hexahedron and a tetrahedron;
!!  - isotropic_d3 is the tensor law lambda tr(eps) I + 2 mu eps for random strains;
!!  - the stiffness of a distorted hexahedron and a tetrahedron, isotropic and anisotropic:
!!    symmetric, K r = 0 for the 3 translations and 3 infinitesimal rotations, and exactly 6
!!    eigenvalues near 0 (a Jacobi eigen-solver written here);
!!  - the patch test: the unit cube in 2x2x2 and 3x3x3 distorted hexahedra (interior nodes
!!    moved, face nodes moved in their plane), and the same cells split by kuhn_tets, the
!!    global stiffness assembled densely here, an affine displacement u = A x + c (A not
!!    symmetric) prescribed on the boundary: the interior nodes reproduce it (Gaussian
!!    elimination here), isotropic and with a random SPD anisotropic D = M'M + 6 I; the stress
!!    of the affine field is D eps(A) in every cell;
!!  - the shape integrals: they sum to the volume (tetrahedra: a triple product; a trilinear
!!    hexahedron: the divergence theorem over its bilinear faces, by Simpson's rule), V/8
!!    each on a parallelepiped, V/4 on a tetrahedron;
!!  - face loads: a triangle's and a planar quadrilateral's sum to t x area (Heron's formula),
!!    their first moment is t x int x dA, a parallelogram's are area/4 each; the area normal
!!    is the polygon's vector area 1/2 sum p_i x p_i+1 (a non-planar quadrilateral too);
!!  - kuhn_tets: 6 positive tetrahedra filling the unit cube, every face of the split met
!!    once (the cube's 12 boundary triangles) or twice (6 interior ones), and two neighbouring
!!    cells cut their shared face into the same triangles, in x, y and z;
!!  - an inverted hexahedron (two vertices swapped) has minjac <= 0 and g = 0 where det <= 0;
!!    an inverted tetrahedron det <= 0, g = 0 and ke = 0.
program test_elements_3d
  use kinds, only: wp, i8
  use elements_3d, only: hex8_gradients, tet4_gradients, isotropic_d3, solid_stiffness, solid_stress, &
                         solid_shape_integrals, face_traction, face_area_normal, kuhn_tets, &
                         HEX8_NVERT, TET4_NVERT, SOLID_MAX_NDOF, NVOIGT, KUHN_NTET
  use testing, only: report, test_summary
  implicit none (type, external)

  real(wp), parameter :: LAM = 1.7_wp, MU = 0.9_wp       ! the isotropic material [stress]
  ! the unit cube's vertices in HEX8 (Gmsh) order
  real(wp), parameter :: CUBE(3, 8) = reshape([0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, &
                                               1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, &
                                               0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
                                               1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 1.0_wp], [3, 8])
  ! the affine displacement u = A x + c of the patch tests (A not symmetric)
  real(wp), parameter :: AFF(3, 3) = reshape([0.31_wp, -0.52_wp, 0.17_wp, 0.74_wp, -0.23_wp, 0.45_wp, &
                                              -0.12_wp, 0.66_wp, 0.28_wp], [3, 3])
  real(wp), parameter :: CAFF(3) = [0.013_wp, -0.021_wp, 0.034_wp]
  real(wp) :: d_iso(NVOIGT, NVOIGT), d_ani(NVOIGT, NVOIGT)
  integer :: n, el, im

  call isotropic_d3(LAM, MU, d_iso)
  d_ani = random_spd_d()
  call gradient_identities()
  call isotropic_law()
  do im = 1, 2
    call rigid_and_spectrum(HEX8_NVERT, im == 2)
    call rigid_and_spectrum(TET4_NVERT, im == 2)
  end do
  do n = 2, 3
    do el = 1, 2
      do im = 1, 2
        call patch(n, merge(HEX8_NVERT, TET4_NVERT, el == 1), im == 2)
      end do
    end do
  end do
  call volumes()
  call faces()
  call kuhn()
  call inverted()
  call test_summary()

contains

  ! ---- independent helpers

  pure real(wp) function triple(a, b, c)
    real(wp), intent(in) :: a(3), b(3), c(3)
    triple = a(1)*(b(2)*c(3) - b(3)*c(2)) - a(2)*(b(1)*c(3) - b(3)*c(1)) + a(3)*(b(1)*c(2) - b(2)*c(1))
  end function triple

  pure function crossp(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
  end function crossp

  !> The area of the triangle p, q, r by Heron's formula (in its stable form).
  pure real(wp) function heron(p, q, r)
    real(wp), intent(in) :: p(3), q(3), r(3)
    real(wp) :: s(3), a, b, c
    s = [norm2(q - p), norm2(r - q), norm2(p - r)]
    a = maxval(s)
    c = minval(s)
    b = sum(s) - a - c
    heron = 0.25_wp*sqrt((a + (b + c))*(c - (a - b))*(c + (a - b))*(a + (b - c)))
  end function heron

  !> The Voigt engineering strain of the displacement gradient a (a(i, j) = d u_i / d x_j).
  pure function voigt_strain(a) result(e)
    real(wp), intent(in) :: a(3, 3)
    real(wp) :: e(6)
    e = [a(1, 1), a(2, 2), a(3, 3), a(2, 3) + a(3, 2), a(1, 3) + a(3, 1), a(1, 2) + a(2, 1)]
  end function voigt_strain

  !> The isotropic stress lambda tr(eps) I + 2 mu eps of the tensor strain of a, in Voigt order.
  pure function iso_stress(a) result(s)
    real(wp), intent(in) :: a(3, 3)
    real(wp) :: s(6), eps(3, 3), sig(3, 3)
    integer :: i
    eps = 0.5_wp*(a + transpose(a))
    sig = 2.0_wp*MU*eps
    do i = 1, 3
      sig(i, i) = sig(i, i) + LAM*(eps(1, 1) + eps(2, 2) + eps(3, 3))
    end do
    s = [sig(1, 1), sig(2, 2), sig(3, 3), sig(2, 3), sig(1, 3), sig(1, 2)]
  end function iso_stress

  !> A deterministic pseudo-random number in [-1, 1) (Park-Miller).
  real(wp) function rnd(state)
    integer, intent(inout) :: state
    state = int(modulo(int(state, i8)*48271_i8, 2147483647_i8))
    rnd = 2.0_wp*real(state, wp)/2147483647.0_wp - 1.0_wp
  end function rnd

  !> A random symmetric positive definite anisotropic stiffness M'M + 6 I.
  function random_spd_d() result(d)
    real(wp) :: d(6, 6), m(6, 6)
    integer :: i, j, st
    st = 20240611
    do j = 1, 6
      do i = 1, 6
        m(i, j) = rnd(st)
      end do
    end do
    d = matmul(transpose(m), m)
    do i = 1, 6
      d(i, i) = d(i, i) + 6.0_wp
    end do
  end function random_spd_d

  !> The eigenvalues of the symmetric a by cyclic Jacobi rotations, ascending.
  subroutine jacobi_eigenvalues(a, ev)
    real(wp), intent(in) :: a(:, :)
    real(wp), intent(out) :: ev(:)
    real(wp) :: b(size(a, 1), size(a, 1)), th, t, c, s, tau, bpq, bip, biq
    integer :: n, p, q, i, sweep
    n = size(a, 1)
    b = a
    do sweep = 1, 100
      if (sqrt(sum(b**2) - sum([(b(i, i)**2, i=1, n)])) <= 1e-18_wp*sqrt(sum(b**2))) exit
      do p = 1, n - 1
        do q = p + 1, n
          bpq = b(p, q)
          if (bpq == 0.0_wp) cycle
          th = (b(q, q) - b(p, p))/(2.0_wp*bpq)
          t = sign(1.0_wp, th)/(abs(th) + sqrt(th*th + 1.0_wp))
          c = 1.0_wp/sqrt(t*t + 1.0_wp)
          s = t*c
          tau = s/(1.0_wp + c)
          b(p, p) = b(p, p) - t*bpq
          b(q, q) = b(q, q) + t*bpq
          b(p, q) = 0.0_wp
          b(q, p) = 0.0_wp
          do i = 1, n
            if (i == p .or. i == q) cycle
            bip = b(i, p)
            biq = b(i, q)
            b(i, p) = bip - s*(biq + tau*bip)
            b(i, q) = biq + s*(bip - tau*biq)
            b(p, i) = b(i, p)
            b(q, i) = b(i, q)
          end do
        end do
      end do
    end do
    ev = [(b(i, i), i=1, n)]
    do p = 1, n - 1          ! insertion sort
      do q = p + 1, n
        if (ev(q) < ev(p)) then
          t = ev(p)
          ev(p) = ev(q)
          ev(q) = t
        end if
      end do
    end do
  end subroutine jacobi_eigenvalues

  !> Solve a x = b by Gaussian elimination with partial pivoting (a, b overwritten).
  subroutine gauss_solve(a, b)
    real(wp), intent(inout) :: a(:, :), b(:)
    integer :: n, k, p, i
    real(wp) :: row(size(a, 2)), t
    n = size(a, 1)
    do k = 1, n
      p = k - 1 + maxloc(abs(a(k:n, k)), 1)
      if (p /= k) then
        row = a(k, :)
        a(k, :) = a(p, :)
        a(p, :) = row
        t = b(k)
        b(k) = b(p)
        b(p) = t
      end if
      do i = k + 1, n
        t = a(i, k)/a(k, k)
        a(i, k:n) = a(i, k:n) - t*a(k, k:n)
        b(i) = b(i) - t*b(k)
      end do
    end do
    do k = n, 1, -1
      b(k) = (b(k) - dot_product(a(k, k + 1:n), b(k + 1:n)))/a(k, k)
    end do
  end subroutine gauss_solve

  !> A distorted hexahedron (non-planar faces) around the box 2 x 1.5 x 1.2.
  function distorted_hex() result(xe)
    real(wp) :: xe(3, 8)
    real(wp), parameter :: pert(3, 8) = reshape([0.10_wp, -0.05_wp, 0.07_wp, -0.08_wp, 0.12_wp, -0.03_wp, &
                                                 0.05_wp, 0.09_wp, 0.11_wp, -0.12_wp, -0.04_wp, 0.06_wp, &
                                                 0.03_wp, 0.10_wp, -0.09_wp, 0.14_wp, -0.07_wp, 0.02_wp, &
                                                 -0.06_wp, 0.05_wp, 0.13_wp, 0.08_wp, -0.11_wp, -0.05_wp], [3, 8])
    xe = CUBE*spread([2.0_wp, 1.5_wp, 1.2_wp], 2, 8) + pert + spread([0.4_wp, -0.3_wp, 1.1_wp], 2, 8)
  end function distorted_hex

  !> A general positively oriented tetrahedron (columns 5:8 garbage, to see they are unused).
  function general_tet() result(xe)
    real(wp) :: xe(3, 8)
    xe = 99.0_wp
    xe(:, 1) = [0.2_wp, -0.1_wp, 0.3_wp]
    xe(:, 2) = [1.4_wp, 0.2_wp, 0.1_wp]
    xe(:, 3) = [0.5_wp, 1.3_wp, -0.2_wp]
    xe(:, 4) = [0.3_wp, 0.4_wp, 1.5_wp]
  end function general_tet

  ! ---- the checks

  subroutine gradient_identities()
    real(wp) :: xe(3, 8), nf(8), g(3, 8), det, worst, eye(3, 3), pts(3, 4), gt(3, 4)
    integer :: q, i
    eye = 0.0_wp
    do i = 1, 3
      eye(i, i) = 1.0_wp
    end do
    pts = reshape([0.0_wp, 0.0_wp, 0.0_wp, 0.3_wp, -0.7_wp, 0.5_wp, -0.9_wp, 0.8_wp, -0.2_wp, &
                   1.0_wp, 1.0_wp, -1.0_wp], [3, 4])
    xe = distorted_hex()
    worst = 0.0_wp
    do q = 1, 4
      call hex8_gradients(xe, pts(1, q), pts(2, q), pts(3, q), nf, g, det)
      worst = max(worst, abs(sum(nf) - 1.0_wp), maxval(abs(sum(g, 2)))*2.0_wp, &
                  maxval(abs(matmul(xe, transpose(g)) - eye)))
    end do
    call report(worst <= 1e-13_wp, 'hex8_gradients: sum N = 1, sum g = 0, sum x_a g_a'' = I at 4 points', &
                worst, 1e-13_wp)
    xe = general_tet()
    call tet4_gradients(xe(:, 1:4), gt, det)
    worst = max(maxval(abs(sum(gt, 2))), maxval(abs(matmul(xe(:, 1:4), transpose(gt)) - eye)), &
                abs(det - triple(xe(:, 2) - xe(:, 1), xe(:, 3) - xe(:, 1), xe(:, 4) - xe(:, 1))))
    call report(worst <= 1e-13_wp, 'tet4_gradients: sum g = 0, sum x_a g_a'' = I, det = the triple product', &
                worst, 1e-13_wp)
  end subroutine gradient_identities

  subroutine isotropic_law()
    real(wp) :: a(3, 3), worst
    integer :: k, i, j, st
    st = 777
    worst = 0.0_wp
    do k = 1, 5
      do j = 1, 3
        do i = 1, 3
          a(i, j) = rnd(st)
        end do
      end do
      worst = max(worst, maxval(abs(matmul(d_iso, voigt_strain(a)) - iso_stress(a))))
    end do
    worst = worst/(LAM + 2*MU)
    call report(worst <= 1e-14_wp, 'isotropic_d3 = lambda tr(eps) I + 2 mu eps (5 random strains, rel)', &
                worst, 1e-14_wp)
  end subroutine isotropic_law

  subroutine rigid_and_spectrum(nv, aniso)
    integer, intent(in) :: nv
    logical, intent(in) :: aniso
    real(wp) :: xe(3, 8), ke(SOLID_MAX_NDOF, SOLID_MAX_NDOF), minjac, r(SOLID_MAX_NDOF), kmax, asym, rig, w(3)
    real(wp), allocatable :: ev(:)
    integer :: nd, k, a, nzero
    character(len=40) :: what
    character(len=12) :: ratio
    what = merge('HEX8', 'TET4', nv == HEX8_NVERT)//merge(' anisotropic', ' isotropic  ', aniso)
    if (nv == HEX8_NVERT) then
      xe = distorted_hex()
    else
      xe = general_tet()
    end if
    call solid_stiffness(nv, xe, merge(d_ani, d_iso, aniso), ke, minjac)
    nd = 3*nv
    kmax = maxval(abs(ke(1:nd, 1:nd)))
    asym = maxval(abs(ke(1:nd, 1:nd) - transpose(ke(1:nd, 1:nd))))/kmax
    rig = 0.0_wp
    do k = 1, 6
      r = 0.0_wp
      do a = 1, nv
        if (k <= 3) then
          r(3*a - 3 + k) = 1.0_wp
        else
          w = 0.0_wp
          w(k - 3) = 1.0_wp
          r(3*a - 2:3*a) = crossp(w, xe(:, a))
        end if
      end do
      rig = max(rig, maxval(abs(matmul(ke(1:nd, 1:nd), r(1:nd))))/(kmax*maxval(abs(r))))
    end do
    allocate (ev(nd))
    call jacobi_eigenvalues(ke(1:nd, 1:nd), ev)
    nzero = count(abs(ev) <= 1e-10_wp*maxval(ev))
    call report(minjac > 0.0_wp .and. asym <= 1e-15_wp .and. all(ke(nd + 1:, :) == 0.0_wp) .and. &
                all(ke(:, nd + 1:) == 0.0_wp), trim(what)//': minjac > 0, ke symmetric (rel), zero beyond its DOFs', &
                asym, 1e-15_wp)
    call report(rig <= 1e-13_wp, trim(what)//': K r = 0 for 3 translations, 3 rotations (rel)', rig, 1e-13_wp)
    write (ratio, '(es9.2)') ev(7)/ev(nd)
    call report(nzero == 6 .and. ev(7) > 1e-6_wp*ev(nd), trim(what)//': exactly 6 eigenvalues <= 1e-10 max '// &
                '(their largest |ev|/max; 7th/max '//trim(adjustl(ratio))//')', maxval(abs(ev(1:6)))/ev(nd), 1e-10_wp)
    if (nzero /= 6) write (*, '(a,i0,a,3es10.2)') '      near-zero eigenvalues: ', nzero, '; ev(5:7)/max = ', &
      ev(5:7)/ev(nd)
  end subroutine rigid_and_spectrum

  !> The patch test on the unit cube in n^3 distorted cells (HEX8, or each cell split by
  !! kuhn_tets): the affine field prescribed on the boundary, reproduced inside; its stress.
  subroutine patch(n, nv, aniso)
    integer, intent(in) :: n, nv
    logical, intent(in) :: aniso
    integer :: nn, nd, i, j, k, c, a, b, e, ncell, nfree, nb, st, cnt
    integer, allocatable :: cells(:, :), free(:), fixed(:)
    integer :: hexv(8), tets(4, 6)
    real(wp), allocatable :: x(:, :), kg(:, :), u(:), uex(:), kff(:, :), rhs(:)
    real(wp) :: xe(3, 8), ke(SOLID_MAX_NDOF, SOLID_MAX_NDOF), ue(SOLID_MAX_NDOF), s(6), sref(6), d(6, 6)
    real(wp) :: minjac, h, uerr, serr, mj
    logical :: bnd(3)
    character(len=60) :: what

    write (what, '(a,i0,a,a,a)') 'patch ', n, '^3 ', merge('HEX8', 'TET4', nv == HEX8_NVERT), &
      merge(' anisotropic', ' isotropic  ', aniso)
    d = merge(d_ani, d_iso, aniso)
    nn = (n + 1)**3
    nd = 3*nn
    h = 1.0_wp/n
    allocate (x(3, nn))
    st = 4242 + n
    do k = 0, n
      do j = 0, n
        do i = 0, n
          a = nid(n, i, j, k)
          x(:, a) = [i, j, k]*h
          bnd = [i == 0 .or. i == n, j == 0 .or. j == n, k == 0 .or. k == n]
          if (count(bnd) == 0) then          ! interior: moved in all directions
            do c = 1, 3
              x(c, a) = x(c, a) + 0.12_wp*h*rnd(st)
            end do
          else if (count(bnd) == 1) then     ! on a face: moved in its plane
            do c = 1, 3
              if (.not. bnd(c)) x(c, a) = x(c, a) + 0.12_wp*h*rnd(st)
            end do
          end if
        end do
      end do
    end do
    ! the cells
    if (nv == HEX8_NVERT) then
      ncell = n**3
    else
      ncell = KUHN_NTET*n**3
    end if
    allocate (cells(nv, ncell))
    e = 0
    do k = 0, n - 1
      do j = 0, n - 1
        do i = 0, n - 1
          hexv = [nid(n, i, j, k), nid(n, i + 1, j, k), nid(n, i + 1, j + 1, k), nid(n, i, j + 1, k), &
                  nid(n, i, j, k + 1), nid(n, i + 1, j, k + 1), nid(n, i + 1, j + 1, k + 1), nid(n, i, j + 1, k + 1)]
          if (nv == HEX8_NVERT) then
            e = e + 1
            cells(:, e) = hexv
          else
            call kuhn_tets(hexv, tets)
            cells(:, e + 1:e + KUHN_NTET) = tets
            e = e + KUHN_NTET
          end if
        end do
      end do
    end do
    ! assemble densely
    allocate (kg(nd, nd))
    kg = 0.0_wp
    mj = huge(1.0_wp)
    do e = 1, ncell
      xe = 0.0_wp
      xe(:, 1:nv) = x(:, cells(:, e))
      call solid_stiffness(nv, xe, d, ke, minjac)
      mj = min(mj, minjac)
      do b = 1, nv
        do a = 1, nv
          kg(3*cells(a, e) - 2:3*cells(a, e), 3*cells(b, e) - 2:3*cells(b, e)) = &
            kg(3*cells(a, e) - 2:3*cells(a, e), 3*cells(b, e) - 2:3*cells(b, e)) + ke(3*a - 2:3*a, 3*b - 2:3*b)
        end do
      end do
    end do
    ! the affine field; the free DOFs (interior nodes) and the prescribed ones
    allocate (uex(nd), u(nd))
    do a = 1, nn
      uex(3*a - 2:3*a) = matmul(AFF, x(:, a)) + CAFF
    end do
    allocate (free(0), fixed(0))
    do k = 0, n
      do j = 0, n
        do i = 0, n
          a = nid(n, i, j, k)
          if (i == 0 .or. i == n .or. j == 0 .or. j == n .or. k == 0 .or. k == n) then
            fixed = [fixed, 3*a - 2, 3*a - 1, 3*a]
          else
            free = [free, 3*a - 2, 3*a - 1, 3*a]
          end if
        end do
      end do
    end do
    nfree = size(free)
    nb = size(fixed)
    u = 0.0_wp
    u(fixed) = uex(fixed)
    kff = kg(free, free)
    rhs = -matmul(kg(free, fixed), u(fixed))
    call gauss_solve(kff, rhs)
    u(free) = rhs
    uerr = maxval(abs(u - uex))/maxval(abs(uex))
    call report(mj > 0.0_wp .and. uerr <= 1e-12_wp, trim(what)//': all cells positive, interior nodes '// &
                'reproduce u = A x + c (rel)', uerr, 1e-12_wp)
    ! the stress of the affine field in every cell
    if (aniso) then
      sref = matmul(d_ani, voigt_strain(AFF))
    else
      sref = iso_stress(AFF)
    end if
    serr = 0.0_wp
    cnt = 0
    do e = 1, ncell
      xe = 0.0_wp
      ue = 0.0_wp
      do a = 1, nv
        xe(:, a) = x(:, cells(a, e))
        ue(3*a - 2:3*a) = uex(3*cells(a, e) - 2:3*cells(a, e))
      end do
      call solid_stress(nv, xe, ue, d, s)
      serr = max(serr, maxval(abs(s - sref)))
      cnt = cnt + 1
    end do
    serr = serr/maxval(abs(sref))
    call report(serr <= 1e-12_wp .and. cnt == ncell, trim(what)//': cell stress of the affine field = '// &
                'D eps(A) (rel)', serr, 1e-12_wp)
  end subroutine patch

  !> The node (i, j, k), 0..n each, of the patch tests' (n + 1)^3 grid.
  pure integer function nid(n, i, j, k)
    integer, intent(in) :: n, i, j, k
    nid = 1 + i + (n + 1)*(j + (n + 1)*k)
  end function nid

  !> The volume of a trilinear hexahedron by the divergence theorem: 1/3 of the flux of x
  !! through its 6 bilinear faces (outward, counter-clockwise seen from outside), each
  !! integrand x . (x_xi x x_eta) of degree 2 in each face coordinate: Simpson exact.
  real(wp) function hex_volume_div(xe)
    real(wp), intent(in) :: xe(3, 8)
    integer, parameter :: fc(4, 6) = reshape([1, 4, 3, 2, 5, 6, 7, 8, 1, 2, 6, 5, 2, 3, 7, 6, 3, 4, 8, 7, &
                                              1, 5, 8, 4], [4, 6])
    real(wp), parameter :: sn(3) = [-1.0_wp, 0.0_wp, 1.0_wp], sw(3) = [1.0_wp, 4.0_wp, 1.0_wp]/3.0_wp
    real(wp) :: p(3, 4), xq(3), dxi(3), deta(3), s, t
    integer :: f, i, j
    hex_volume_div = 0.0_wp
    do f = 1, 6
      p = xe(:, fc(:, f))
      do j = 1, 3
        do i = 1, 3
          s = sn(i)
          t = sn(j)
          xq = 0.25_wp*((1 - s)*(1 - t)*p(:, 1) + (1 + s)*(1 - t)*p(:, 2) + (1 + s)*(1 + t)*p(:, 3) + &
                        (1 - s)*(1 + t)*p(:, 4))
          dxi = 0.25_wp*(-(1 - t)*p(:, 1) + (1 - t)*p(:, 2) + (1 + t)*p(:, 3) - (1 + t)*p(:, 4))
          deta = 0.25_wp*(-(1 - s)*p(:, 1) - (1 + s)*p(:, 2) + (1 + s)*p(:, 3) + (1 - s)*p(:, 4))
          hex_volume_div = hex_volume_div + sw(i)*sw(j)*dot_product(xq, crossp(dxi, deta))
        end do
      end do
    end do
    hex_volume_div = hex_volume_div/3.0_wp
  end function hex_volume_div

  subroutine volumes()
    real(wp) :: xe(3, 8), w(8), v, err1, err2, a(3), b(3), c(3), x0(3)
    integer :: q
    ! the divergence theorem's volume of the unit cube first: its face table is right
    v = hex_volume_div(CUBE)
    call report(abs(v - 1.0_wp) <= 1e-14_wp, 'reference: the divergence-theorem volume of the unit cube is 1', &
                abs(v - 1.0_wp), 1e-14_wp)
    xe = distorted_hex()
    call solid_shape_integrals(HEX8_NVERT, xe, w)
    v = hex_volume_div(xe)
    err1 = abs(sum(w) - v)/v
    call report(err1 <= 1e-14_wp .and. all(w > 0.0_wp), 'HEX8 distorted: sum of shape integrals = the '// &
                'divergence-theorem volume (rel)', err1, 1e-14_wp)
    ! a parallelepiped x0 + s a + t b + r c, s, t, r in [0, 1]
    a = [1.3_wp, 0.2_wp, -0.1_wp]
    b = [0.4_wp, 0.9_wp, 0.3_wp]
    c = [-0.2_wp, 0.35_wp, 1.1_wp]
    x0 = [0.5_wp, -0.7_wp, 0.2_wp]
    do q = 1, 8
      xe(:, q) = x0 + CUBE(1, q)*a + CUBE(2, q)*b + CUBE(3, q)*c
    end do
    v = triple(a, b, c)
    call solid_shape_integrals(HEX8_NVERT, xe, w)
    err2 = maxval(abs(w - v/8.0_wp))/v
    call report(err2 <= 1e-14_wp, 'HEX8 parallelepiped: each shape integral = V/8, V a triple product (rel)', &
                err2, 1e-14_wp)
    xe = general_tet()
    v = triple(xe(:, 2) - xe(:, 1), xe(:, 3) - xe(:, 1), xe(:, 4) - xe(:, 1))/6.0_wp
    call solid_shape_integrals(TET4_NVERT, xe, w)
    err1 = max(maxval(abs(w(1:4) - v/4.0_wp)), abs(sum(w) - v))/v
    call report(err1 <= 1e-14_wp .and. all(w(5:8) == 0.0_wp), 'TET4: each shape integral = V/4, sum = V (rel)', &
                err1, 1e-14_wp)
  end subroutine volumes

  subroutine faces()
    real(wp) :: xf(3, 4), fe(3, 4), an(3), t(3), area, err, mom(3, 3), ref(3, 3), c1(3), c2(3), a1, a2, van(3)
    integer :: i, a
    t = [0.7_wp, -1.3_wp, 2.1_wp]
    ! a triangle in space
    xf = 0.0_wp
    xf(:, 1) = [0.1_wp, 0.2_wp, 0.3_wp]
    xf(:, 2) = [1.2_wp, -0.1_wp, 0.5_wp]
    xf(:, 3) = [0.4_wp, 0.9_wp, -0.3_wp]
    xf(:, 4) = 99.0_wp
    area = heron(xf(:, 1), xf(:, 2), xf(:, 3))
    call face_traction(3, xf, t, fe)
    err = 0.0_wp
    do a = 1, 3
      err = max(err, maxval(abs(fe(:, a) - t*area/3.0_wp)))
    end do
    err = err/maxval(abs(t*area))
    call report(err <= 1e-14_wp .and. all(fe(:, 4) == 0.0_wp), 'face_traction triangle: t area/3 each, '// &
                'Heron''s area (rel)', err, 1e-14_wp)
    call face_area_normal(3, xf, an)
    van = 0.5_wp*(crossp(xf(:, 1), xf(:, 2)) + crossp(xf(:, 2), xf(:, 3)) + crossp(xf(:, 3), xf(:, 1)))
    err = max(maxval(abs(an - van)), abs(norm2(an) - area))/area
    call report(err <= 1e-14_wp, 'face_area_normal triangle: the vector area, |an| = Heron''s area (rel)', &
                err, 1e-14_wp)
    ! a planar quadrilateral (not a parallelogram), turned into space: the plane
    ! p0 + s e1 + r e2 with e1, e2 not orthogonal
    xf(:, 1) = quad_pt(0.0_wp, 0.0_wp)
    xf(:, 2) = quad_pt(2.0_wp, 0.1_wp)
    xf(:, 3) = quad_pt(1.6_wp, 1.4_wp)
    xf(:, 4) = quad_pt(-0.2_wp, 0.9_wp)
    a1 = heron(xf(:, 1), xf(:, 2), xf(:, 3))
    a2 = heron(xf(:, 1), xf(:, 3), xf(:, 4))
    c1 = (xf(:, 1) + xf(:, 2) + xf(:, 3))/3.0_wp
    c2 = (xf(:, 1) + xf(:, 3) + xf(:, 4))/3.0_wp
    area = a1 + a2
    call face_traction(4, xf, t, fe)
    err = maxval(abs(sum(fe, 2) - t*area))/maxval(abs(t*area))
    call report(err <= 1e-14_wp, 'face_traction planar quadrilateral: sum = t area, Heron''s area (rel)', &
                err, 1e-14_wp)
    ! first moment: sum_a fe_a x_a' = t (int x dA)' (sum N_a x_a = x)
    mom = matmul(fe, transpose(xf))
    do i = 1, 3
      ref(:, i) = t*(a1*c1(i) + a2*c2(i))
    end do
    err = maxval(abs(mom - ref))/maxval(abs(ref))
    call report(err <= 1e-14_wp, 'face_traction planar quadrilateral: first moment = t int x dA (rel)', &
                err, 1e-14_wp)
    call face_area_normal(4, xf, an)
    err = abs(norm2(an) - area)/area
    call report(err <= 1e-14_wp, 'face_area_normal planar quadrilateral: |an| = Heron''s area (rel)', &
                err, 1e-14_wp)
    ! a parallelogram: area/4 each
    xf(:, 1) = quad_pt(0.0_wp, 0.0_wp)
    xf(:, 2) = quad_pt(1.5_wp, 0.0_wp)
    xf(:, 3) = quad_pt(2.1_wp, 0.8_wp)
    xf(:, 4) = quad_pt(0.6_wp, 0.8_wp)
    area = 2.0_wp*heron(xf(:, 1), xf(:, 2), xf(:, 3))
    call face_traction(4, xf, t, fe)
    err = 0.0_wp
    do a = 1, 4
      err = max(err, maxval(abs(fe(:, a) - t*area/4.0_wp)))
    end do
    err = err/maxval(abs(t*area))
    call report(err <= 1e-14_wp, 'face_traction parallelogram: t area/4 each (rel)', err, 1e-14_wp)
    ! a non-planar quadrilateral: the area normal is the polygon's vector area
    xf(:, 1) = [0.0_wp, 0.0_wp, 0.0_wp]
    xf(:, 2) = [1.0_wp, 0.1_wp, 0.3_wp]
    xf(:, 3) = [1.1_wp, 1.2_wp, -0.2_wp]
    xf(:, 4) = [-0.1_wp, 0.9_wp, 0.25_wp]
    call face_area_normal(4, xf, an)
    van = 0.0_wp
    do a = 1, 4
      van = van + 0.5_wp*crossp(xf(:, a), xf(:, modulo(a, 4) + 1))
    end do
    err = maxval(abs(an - van))/norm2(van)
    call report(err <= 1e-14_wp, 'face_area_normal non-planar quadrilateral: 1/2 sum p_i x p_i+1 (rel)', &
                err, 1e-14_wp)
  end subroutine faces

  !> A point (s, r) of the plane p0 + s e1 + r e2 (e1, e2 not orthogonal, not unit).
  pure function quad_pt(s, r) result(p)
    real(wp), intent(in) :: s, r
    real(wp) :: p(3)
    p = [0.3_wp, -0.2_wp, 0.5_wp] + s*[0.8_wp, 0.3_wp, -0.4_wp] + r*[0.1_wp, 0.7_wp, 0.6_wp]
  end function quad_pt

  subroutine kuhn()
    integer :: tets(4, 6), tb(4, 6), f(3, 24), nf, i, j, dir, va(8), vb(8), sa(3, 12), sb(3, 12)
    integer :: na, nb, once, twice, mult
    real(wp) :: vol, vmin, vt
    logical :: same
    call kuhn_tets([(i, i=1, 8)], tets)
    vol = 0.0_wp
    vmin = huge(1.0_wp)
    do i = 1, 6
      associate (p => CUBE(:, tets(:, i)))
        vt = triple(p(:, 2) - p(:, 1), p(:, 3) - p(:, 1), p(:, 4) - p(:, 1))/6.0_wp
      end associate
      vmin = min(vmin, vt)
      vol = vol + vt
    end do
    call report(vmin > 0.0_wp .and. abs(vol - 1.0_wp) <= 1e-14_wp .and. all(tets(1, :) == 1) .and. &
                all(tets(4, :) == 7), 'kuhn_tets unit cube: 6 positive tets on the diagonal v1-v7, volumes sum to 1', &
                abs(vol - 1.0_wp), 1e-14_wp)
    ! the faces of the split: 12 met once (the cube's boundary, two per face), 6 twice
    nf = 0
    do i = 1, 6
      call tet_faces(tets(:, i), f(:, nf + 1:nf + 4))
      nf = nf + 4
    end do
    once = 0
    twice = 0
    do i = 1, nf
      mult = 0
      do j = 1, nf
        if (all(f(:, i) == f(:, j))) mult = mult + 1
      end do
      if (mult == 1) once = once + 1
      if (mult == 2) twice = twice + 1
    end do
    call report(once == 12 .and. twice == 12, 'kuhn_tets: 12 boundary triangles, 6 interior ones met twice')
    ! neighbouring cells in x, y, z: the shared face cut alike from both sides
    same = .true.
    do dir = 1, 3
      call neighbours(dir, va, vb)
      call kuhn_tets(va, tets)
      call kuhn_tets(vb, tb)
      call faces_on(tets, dir, sa, na)
      call faces_on(tb, dir, sb, nb)
      same = same .and. na == 2 .and. nb == 2 .and. sets_equal(sa(:, 1:na), sb(:, 1:nb))
    end do
    call report(same, 'kuhn_tets: two neighbouring cells (x, y and z) cut their shared face into the same 2 triangles')

  end subroutine kuhn

  !> Cells A (at the origin) and B (A shifted by one along dir) of a grid of nodes
  !! numbered 1 + i + 3 j + 9 k, i, j, k in 0..2: their HEX8 vertex ids. They share the
  !! face at grid coordinate dir = 1.
  subroutine neighbours(dir, va, vb)
    integer, intent(in) :: dir
    integer, intent(out) :: va(8), vb(8)
    integer :: q, off(3)
    off = 0
    off(dir) = 1
    do q = 1, 8
      va(q) = gid(nint(CUBE(:, q)))
      vb(q) = gid(nint(CUBE(:, q)) + off)
    end do
  end subroutine neighbours

  integer function gid(ijk)
    integer, intent(in) :: ijk(3)
    gid = 1 + ijk(1) + 3*ijk(2) + 9*ijk(3)
  end function gid

  !> The triangles (sorted vertex ids) of the tets' faces in the plane grid coordinate dir = 1.
  subroutine faces_on(tt, dir, s, ns)
    integer, intent(in) :: tt(4, 6), dir
    integer, intent(out) :: s(3, 12), ns
    integer :: ff(3, 4), q, r, c
    ns = 0
    s = 0
    do q = 1, 6
      call tet_faces(tt(:, q), ff)
      do r = 1, 4
        if (all([(coord(ff(c, r), dir), c=1, 3)] == 1)) then
          ns = ns + 1
          s(:, ns) = ff(:, r)
        end if
      end do
    end do
  end subroutine faces_on

  integer function coord(id, dir)
    integer, intent(in) :: id, dir
    integer :: ijk(3)
    ijk = [mod(id - 1, 3), mod((id - 1)/3, 3), (id - 1)/9]
    coord = ijk(dir)
  end function coord

  !> The 4 faces of a tetrahedron as sorted vertex triples.
  subroutine tet_faces(t, f)
    integer, intent(in) :: t(4)
    integer, intent(out) :: f(3, 4)
    f(:, 1) = sort3([t(2), t(3), t(4)])
    f(:, 2) = sort3([t(1), t(3), t(4)])
    f(:, 3) = sort3([t(1), t(2), t(4)])
    f(:, 4) = sort3([t(1), t(2), t(3)])
  end subroutine tet_faces

  pure function sort3(v) result(s)
    integer, intent(in) :: v(3)
    integer :: s(3)
    s = [minval(v), sum(v) - minval(v) - maxval(v), maxval(v)]
  end function sort3

  !> Two lists of sorted triples hold the same triples (each of one found in the other, same count).
  logical function sets_equal(a, b)
    integer, intent(in) :: a(:, :), b(:, :)
    integer :: i, j
    logical :: found
    sets_equal = size(a, 2) == size(b, 2)
    do i = 1, size(a, 2)
      found = .false.
      do j = 1, size(b, 2)
        if (all(a(:, i) == b(:, j))) found = .true.
      end do
      sets_equal = sets_equal .and. found
    end do
  end function sets_equal

  subroutine inverted()
    real(wp) :: xe(3, 8), ke(SOLID_MAX_NDOF, SOLID_MAX_NDOF), minjac, nf(8), g(3, 8), det, gt(3, 4)
    xe = CUBE
    xe(:, 1) = CUBE(:, 2)
    xe(:, 2) = CUBE(:, 1)
    call solid_stiffness(HEX8_NVERT, xe, d_iso, ke, minjac)
    call report(minjac <= 0.0_wp, 'HEX8 with vertices 1 and 2 swapped: minjac <= 0', minjac)
    call hex8_gradients(xe, -1.0_wp, -1.0_wp, -1.0_wp, nf, g, det)
    call report(det < 0.0_wp .and. all(g == 0.0_wp), 'HEX8 swapped: det < 0 at its corner 1 and g = 0 there', det)
    xe = general_tet()
    xe(:, 3) = general_tet_col(4)
    xe(:, 4) = general_tet_col(3)
    call tet4_gradients(xe(:, 1:4), gt, det)
    call solid_stiffness(TET4_NVERT, xe, d_iso, ke, minjac)
    call report(det <= 0.0_wp .and. all(gt == 0.0_wp) .and. minjac == det .and. all(ke == 0.0_wp), &
                'TET4 with vertices 3 and 4 swapped: det <= 0, g = 0, minjac = det, ke = 0', det)
  end subroutine inverted

  function general_tet_col(k) result(p)
    integer, intent(in) :: k
    real(wp) :: p(3), xe(3, 8)
    xe = general_tet()
    p = xe(:, k)
  end function general_tet_col

end program test_elements_3d
