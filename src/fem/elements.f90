!> Element kernels of plane linear elasticity: shape functions and their gradients,
!! element stiffness, element loads (edge tractions, body force) and element stress,
!! for the bilinear quadrilateral (Q1, 2x2 Gauss) and the linear triangle (P1, exact).
!!
!! Every kernel takes the element's vertex coordinates `xe(2, MAX_NVERT)` (counter-
!! clockwise, the first 3 used by P1), never grid indices, so it serves any mesh of
!! these elements. Element DOFs are interleaved: vertex a, component c (1 = x, 2 = y)
!! is local dof 2*(a-1)+c. Isotropic material given by its (effective) Lame parameters.
!! Units are the deck's, consistently: [length], [stress] = [force]/[length]^2, forces
!! per unit thickness.
module elements
  use kinds, only: wp
  use config, only: ELEM_Q1, ELEM_P1
  implicit none (type, external)
  private

  public :: element_nvert, q1_gradients, p1_gradients, element_stiffness, ke_cache_init
  public :: element_body_force, edge_traction, element_stress, body_force_fn, element_shape_integrals
  public :: element_stress_general, axi_stiffness, axi_stress

  integer, parameter, public :: MAX_NVERT = 4            !< most vertices of an element (Q1)
  integer, parameter, public :: MAX_NDOF = 2*MAX_NVERT   !< most DOFs of an element (Q1)

  abstract interface
    !> A body force density b(x) [force/length^3] (per unit thickness: [force/length^2]/[length]).
    subroutine body_force_fn(x, b)
      import :: wp
      real(wp), intent(in) :: x(:)         !< position (NDIM) [length]
      real(wp), intent(out) :: b(:)        !< body force density (NCOMP) [force/length^3]
    end subroutine body_force_fn
  end interface

  !> Cache of the last element stiffness computed: a cell that is a translate of it (as
  !! on a uniform grid) reuses it. Set it up with `ke_cache_init`.
  type, public :: ke_cache_t
    private
    logical :: valid = .false.
    integer :: element = 0                   ! the element of the cached stiffness
    integer :: key = 0                       ! the material of the cached stiffness (the caller's number)
    real(wp) :: rel(2, MAX_NVERT) = 0.0_wp   ! vertex coordinates relative to vertex 1 [length]
    real(wp) :: tol = 0.0_wp                 ! coordinate tolerance below which cells are the same [length]
    real(wp) :: ke(MAX_NDOF, MAX_NDOF) = 0.0_wp
    real(wp) :: minjac = 0.0_wp
  end type ke_cache_t

  real(wp), parameter :: xa_q1(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]  ! reference nodes of Q1
  real(wp), parameter :: ea_q1(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: gp2 = 0.577350269189625764509148780502_wp      ! 1/sqrt(3)
  ! The 2x2 Gauss points of the Q1 stiffness, eta outer and xi inner, and the reference
  ! derivatives of the shape functions there, by q1_gradients's formulas (the same values).
  integer :: ia_, iq_   ! the implied-do indices of the two tables
  real(wp), parameter :: xi_g2(4) = [-gp2, gp2, -gp2, gp2]
  real(wp), parameter :: eta_g2(4) = [-gp2, -gp2, gp2, gp2]
  real(wp), parameter :: dxi_g2(4, 4) = reshape([((0.25_wp*xa_q1(ia_)*(1.0_wp + eta_g2(iq_)*ea_q1(ia_)), &
                                                    ia_=1, 4), iq_=1, 4)], [4, 4])
  real(wp), parameter :: deta_g2(4, 4) = reshape([((0.25_wp*ea_q1(ia_)*(1.0_wp + xi_g2(iq_)*xa_q1(ia_)), &
                                                     ia_=1, 4), iq_=1, 4)], [4, 4])

contains

  !> Number of vertices of an element: 4 for ELEM_Q1, 3 for ELEM_P1.
  pure integer function element_nvert(element)
    integer, intent(in) :: element   !< ELEM_Q1 or ELEM_P1 (module config)
    element_nvert = 4
    if (element == ELEM_P1) element_nvert = 3
  end function element_nvert

  !> An empty cache whose cells count as the same when their vertex offsets agree to
  !! 16 eps times `coord_max`, the largest absolute coordinate of the mesh [length].
  pure subroutine ke_cache_init(cache, coord_max)
    type(ke_cache_t), intent(out) :: cache    !< the cache
    real(wp), intent(in) :: coord_max         !< largest absolute node coordinate [length]
    cache%tol = 16.0_wp*epsilon(1.0_wp)*max(coord_max, tiny(1.0_wp))
  end subroutine ke_cache_init

  !> Shape functions and their x, y gradients of the bilinear quadrilateral at the
  !! reference point (xi, eta) in [-1,1]^2. Where the Jacobian is not positive, g = 0.
  pure subroutine q1_gradients(xe, xi, eta, nfun, g, det)
    real(wp), intent(in) :: xe(2, MAX_NVERT)   !< vertex coordinates [length]
    real(wp), intent(in) :: xi                 !< reference coordinate xi [-]
    real(wp), intent(in) :: eta                !< reference coordinate eta [-]
    real(wp), intent(out) :: nfun(4)           !< shape functions [-]
    real(wp), intent(out) :: g(2, MAX_NVERT)   !< (d/dx, d/dy) of each shape function [1/length]
    real(wp), intent(out) :: det               !< Jacobian determinant [length^2]
    real(wp) :: dxi(4), deta(4), j11, j12, j21, j22
    integer :: a
    do a = 1, 4
      nfun(a) = 0.25_wp*(1.0_wp + xi*xa_q1(a))*(1.0_wp + eta*ea_q1(a))
      dxi(a) = 0.25_wp*xa_q1(a)*(1.0_wp + eta*ea_q1(a))
      deta(a) = 0.25_wp*ea_q1(a)*(1.0_wp + xi*xa_q1(a))
    end do
    j11 = sum(dxi*xe(1, :))
    j12 = sum(dxi*xe(2, :))
    j21 = sum(deta*xe(1, :))
    j22 = sum(deta*xe(2, :))
    det = j11*j22 - j12*j21
    if (det > 0.0_wp) then
      do a = 1, 4
        g(1, a) = (j22*dxi(a) - j12*deta(a))/det
        g(2, a) = (-j21*dxi(a) + j11*deta(a))/det
      end do
    else
      g = 0.0_wp
    end if
  end subroutine q1_gradients

  !> Constant gradients of the linear triangle's shape functions. Where the triangle is
  !! not counter-clockwise (det <= 0), g = 0.
  pure subroutine p1_gradients(xe, g, det)
    real(wp), intent(in) :: xe(2, MAX_NVERT)   !< vertex coordinates, the first 3 used [length]
    real(wp), intent(out) :: g(2, MAX_NVERT)   !< (d/dx, d/dy) of each shape function, column 4 = 0 [1/length]
    real(wp), intent(out) :: det               !< twice the signed area [length^2]
    det = (xe(1, 2) - xe(1, 1))*(xe(2, 3) - xe(2, 1)) - (xe(1, 3) - xe(1, 1))*(xe(2, 2) - xe(2, 1))
    g = 0.0_wp
    if (det > 0.0_wp) then
      g(1, 1) = (xe(2, 2) - xe(2, 3))/det
      g(2, 1) = (xe(1, 3) - xe(1, 2))/det
      g(1, 2) = (xe(2, 3) - xe(2, 1))/det
      g(2, 2) = (xe(1, 1) - xe(1, 3))/det
      g(1, 3) = (xe(2, 1) - xe(2, 2))/det
      g(2, 3) = (xe(1, 2) - xe(1, 1))/det
    end if
  end subroutine p1_gradients

  !> Add w * B^T D B to ke for the gradients g of nv shape functions (isotropic D).
  !! The material factors of vertex a (c11 g(1, a), ...) are formed once; each entry
  !! adds its two products in turn, as ke + c11 g(1, a) g(1, b) w + mu g(2, a) g(2, b) w.
  pure subroutine add_btdb(nv, g, w, lame_lambda, lame_mu, ke)
    integer, intent(in) :: nv
    real(wp), intent(in) :: g(2, MAX_NVERT), w, lame_lambda, lame_mu
    real(wp), intent(inout) :: ke(MAX_NDOF, MAX_NDOF)
    integer :: a, b
    real(wp) :: c11, xb, yb, cx(MAX_NVERT), cy(MAX_NVERT), lx(MAX_NVERT), ly(MAX_NVERT), &
                mx(MAX_NVERT), my(MAX_NVERT)
    c11 = lame_lambda + 2.0_wp*lame_mu
    do a = 1, nv
      cx(a) = c11*g(1, a)
      cy(a) = c11*g(2, a)
      lx(a) = lame_lambda*g(1, a)
      ly(a) = lame_lambda*g(2, a)
      mx(a) = lame_mu*g(1, a)
      my(a) = lame_mu*g(2, a)
    end do
    do b = 1, nv
      xb = g(1, b)*w
      yb = g(2, b)*w
      do a = 1, nv
        ke(2*a - 1, 2*b - 1) = ke(2*a - 1, 2*b - 1) + cx(a)*xb + my(a)*yb
        ke(2*a, 2*b - 1) = ke(2*a, 2*b - 1) + ly(a)*xb + mx(a)*yb
        ke(2*a - 1, 2*b) = ke(2*a - 1, 2*b) + lx(a)*yb + my(a)*xb
        ke(2*a, 2*b) = ke(2*a, 2*b) + cy(a)*yb + mx(a)*xb
      end do
    end do
  end subroutine add_btdb

  !> The Q1 stiffness by 2x2 Gauss from the tabulated reference derivatives: at each
  !! point the Jacobian, the gradients and w B^T D B with w = det (the Gauss weights are
  !! 1), with the operations of q1_gradients and add_btdb in their order, so the result
  !! is theirs bit for bit. A point where det is not positive adds zeros (gradients and
  !! weight 0), as add_btdb skipped there. Each column of the four 4x4 blocks (xx, yx, xy,
  !! yy) is summed over the points (the loops unrolled, so the sums stay in registers)
  !! and then interleaved into ke.
  !! minjac = the smallest determinant at the points.
  pure subroutine q1_stiffness(xe, lame_lambda, lame_mu, ke, minjac)
    real(wp), intent(in) :: xe(2, MAX_NVERT), lame_lambda, lame_mu
    real(wp), intent(out) :: ke(MAX_NDOF, MAX_NDOF), minjac
    real(wp) :: j11, j12, j21, j22, det, c11, xb, yb
    real(wp) :: w(4), gx(4, 4), gy(4, 4), cx(4, 4), cy(4, 4), lx(4, 4), ly(4, 4), mx(4, 4), my(4, 4)
    real(wp) :: axx(4), ayx(4), axy(4), ayy(4)
    integer :: q, a, b
    c11 = lame_lambda + 2.0_wp*lame_mu
    minjac = huge(1.0_wp)
    do q = 1, 4
      j11 = dxi_g2(1, q)*xe(1, 1) + dxi_g2(2, q)*xe(1, 2) + dxi_g2(3, q)*xe(1, 3) + dxi_g2(4, q)*xe(1, 4)
      j12 = dxi_g2(1, q)*xe(2, 1) + dxi_g2(2, q)*xe(2, 2) + dxi_g2(3, q)*xe(2, 3) + dxi_g2(4, q)*xe(2, 4)
      j21 = deta_g2(1, q)*xe(1, 1) + deta_g2(2, q)*xe(1, 2) + deta_g2(3, q)*xe(1, 3) + deta_g2(4, q)*xe(1, 4)
      j22 = deta_g2(1, q)*xe(2, 1) + deta_g2(2, q)*xe(2, 2) + deta_g2(3, q)*xe(2, 3) + deta_g2(4, q)*xe(2, 4)
      det = j11*j22 - j12*j21
      minjac = min(minjac, det)
      if (det > 0.0_wp) then
        w(q) = det
        gx(:, q) = (j22*dxi_g2(:, q) - j12*deta_g2(:, q))/det
        gy(:, q) = (-j21*dxi_g2(:, q) + j11*deta_g2(:, q))/det
      else
        w(q) = 0.0_wp
        gx(:, q) = 0.0_wp
        gy(:, q) = 0.0_wp
      end if
      cx(:, q) = c11*gx(:, q)
      cy(:, q) = c11*gy(:, q)
      lx(:, q) = lame_lambda*gx(:, q)
      ly(:, q) = lame_lambda*gy(:, q)
      mx(:, q) = lame_mu*gx(:, q)
      my(:, q) = lame_mu*gy(:, q)
    end do
    do b = 1, 4
      axx = 0.0_wp
      ayx = 0.0_wp
      axy = 0.0_wp
      ayy = 0.0_wp
!GCC$ unroll 4
      do q = 1, 4
        xb = gx(b, q)*w(q)
        yb = gy(b, q)*w(q)
!GCC$ unroll 4
        do a = 1, 4
          axx(a) = axx(a) + cx(a, q)*xb + my(a, q)*yb
          ayx(a) = ayx(a) + ly(a, q)*xb + mx(a, q)*yb
          axy(a) = axy(a) + lx(a, q)*yb + my(a, q)*xb
          ayy(a) = ayy(a) + cy(a, q)*yb + mx(a, q)*xb
        end do
      end do
      do a = 1, 4
        ke(2*a - 1, 2*b - 1) = axx(a)
        ke(2*a, 2*b - 1) = ayx(a)
        ke(2*a - 1, 2*b) = axy(a)
        ke(2*a, 2*b) = ayy(a)
      end do
    end do
  end subroutine q1_stiffness

  !> Element stiffness (Q1: 2x2 Gauss; P1: exact) and the smallest Jacobian determinant
  !! met, which is not positive for an inverted or degenerate element. The material is
  !! isotropic (lame_lambda, lame_mu), or any plane stiffness `dmat` (then the Lame
  !! parameters are not used). With `cache`, a cell that is a translate of the last one
  !! computed, of the same material `key`, reuses its stiffness.
  pure subroutine element_stiffness(element, xe, lame_lambda, lame_mu, ke, minjac, cache, dmat, key)
    integer, intent(in) :: element                          !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)                !< vertex coordinates [length]
    real(wp), intent(in) :: lame_lambda                     !< (effective) first Lame parameter [stress]
    real(wp), intent(in) :: lame_mu                         !< shear modulus [stress]
    real(wp), intent(out) :: ke(MAX_NDOF, MAX_NDOF)         !< element stiffness [stress]
    real(wp), intent(out) :: minjac                         !< smallest Jacobian determinant [length^2]
    type(ke_cache_t), intent(inout), optional :: cache      !< the last stiffness computed
    !> (3, 3) the plane stiffness, (sxx, syy, sxy) = dmat (exx, eyy, gxy) [stress]
    real(wp), intent(in), optional :: dmat(:, :)
    integer, intent(in), optional :: key                    !< the material's number for the cache (default 0)
    real(wp) :: rel(2, MAX_NVERT), g(2, MAX_NVERT), det
    integer :: nv, a, k, q

    nv = element_nvert(element)
    k = 0
    if (present(key)) k = key
    if (present(cache)) then
      do a = 1, nv
        rel(:, a) = xe(:, a) - xe(:, 1)
      end do
      if (cache%valid .and. cache%element == element .and. cache%key == k) then
        if (all(abs(rel(:, 1:nv) - cache%rel(:, 1:nv)) <= cache%tol)) then
          ke = cache%ke
          minjac = cache%minjac
          return
        end if
      end if
    end if

    if (present(dmat)) then
      ke = 0.0_wp
      if (element == ELEM_Q1) then
        minjac = huge(1.0_wp)
        do q = 1, 4      ! the tabulated 2x2 Gauss points, as q1_stiffness
          call q1_point(xe, q, g, det)
          minjac = min(minjac, det)
          if (det > 0.0_wp) call add_btdb_general(4, g, det, dmat, ke)
        end do
      else
        call p1_gradients(xe, g, det)
        minjac = det
        if (det > 0.0_wp) call add_btdb_general(3, g, 0.5_wp*det, dmat, ke)
      end if
    else if (element == ELEM_Q1) then
      call q1_stiffness(xe, lame_lambda, lame_mu, ke, minjac)
    else
      ke = 0.0_wp
      call p1_gradients(xe, g, det)
      minjac = det
      if (det > 0.0_wp) call add_btdb(3, g, 0.5_wp*det, lame_lambda, lame_mu, ke)
    end if
    if (present(cache)) then
      cache%valid = .true.
      cache%element = element
      cache%key = k
      cache%rel(:, 1:nv) = rel(:, 1:nv)
      cache%ke = ke
      cache%minjac = minjac
    end if
  end subroutine element_stiffness

  !> Add w B' D B to ke for the gradients g of nv shape functions and any plane stiffness D;
  !! B of vertex a maps (ux, uy) to (exx, eyy, gxy): [gx 0; 0 gy; gy gx].
  pure subroutine add_btdb_general(nv, g, w, dmat, ke)
    integer, intent(in) :: nv
    real(wp), intent(in) :: g(2, MAX_NVERT), w, dmat(:, :)
    real(wp), intent(inout) :: ke(MAX_NDOF, MAX_NDOF)
    real(wp) :: d11, d12, d13, d22, d23, d33, gx, gy, p1, p2, p3, q1, q2, q3
    integer :: a, b
    d11 = dmat(1, 1)*w
    d12 = dmat(1, 2)*w
    d13 = dmat(1, 3)*w
    d22 = dmat(2, 2)*w
    d23 = dmat(2, 3)*w
    d33 = dmat(3, 3)*w
    do b = 1, nv
      gx = g(1, b)
      gy = g(2, b)
      ! w D B_b: its ux column (p) and its uy column (q); D symmetric
      p1 = d11*gx + d13*gy
      p2 = d12*gx + d23*gy
      p3 = d13*gx + d33*gy
      q1 = d12*gy + d13*gx
      q2 = d22*gy + d23*gx
      q3 = d23*gy + d33*gx
      do a = 1, nv
        ke(2*a - 1, 2*b - 1) = ke(2*a - 1, 2*b - 1) + g(1, a)*p1 + g(2, a)*p3
        ke(2*a, 2*b - 1) = ke(2*a, 2*b - 1) + g(2, a)*p2 + g(1, a)*p3
        ke(2*a - 1, 2*b) = ke(2*a - 1, 2*b) + g(1, a)*q1 + g(2, a)*q3
        ke(2*a, 2*b) = ke(2*a, 2*b) + g(2, a)*q2 + g(1, a)*q3
      end do
    end do
  end subroutine add_btdb_general

  !> The gradients and the Jacobian determinant of the Q1 shape functions at the q-th 2x2
  !! Gauss point, from the tabulated reference derivatives (q1_stiffness's arithmetic); g = 0
  !! where det is not positive.
  pure subroutine q1_point(xe, q, g, det)
    real(wp), intent(in) :: xe(2, MAX_NVERT)
    integer, intent(in) :: q
    real(wp), intent(out) :: g(2, MAX_NVERT), det
    real(wp) :: j11, j12, j21, j22
    j11 = dxi_g2(1, q)*xe(1, 1) + dxi_g2(2, q)*xe(1, 2) + dxi_g2(3, q)*xe(1, 3) + dxi_g2(4, q)*xe(1, 4)
    j12 = dxi_g2(1, q)*xe(2, 1) + dxi_g2(2, q)*xe(2, 2) + dxi_g2(3, q)*xe(2, 3) + dxi_g2(4, q)*xe(2, 4)
    j21 = deta_g2(1, q)*xe(1, 1) + deta_g2(2, q)*xe(1, 2) + deta_g2(3, q)*xe(1, 3) + deta_g2(4, q)*xe(1, 4)
    j22 = deta_g2(1, q)*xe(2, 1) + deta_g2(2, q)*xe(2, 2) + deta_g2(3, q)*xe(2, 3) + deta_g2(4, q)*xe(2, 4)
    det = j11*j22 - j12*j21
    if (det > 0.0_wp) then
      g(1, :) = (j22*dxi_g2(:, q) - j12*deta_g2(:, q))/det
      g(2, :) = (-j21*dxi_g2(:, q) + j11*deta_g2(:, q))/det
    else
      g = 0.0_wp
    end if
  end subroutine q1_point

  !> Add the consistent nodal loads of a body force density to `fe`: Q1 3x3 Gauss,
  !! P1 the 3-point interior rule of degree 2; with `axisymmetric`, per radian (b r).
  subroutine element_body_force(element, xe, bf, fe, axisymmetric)
    integer, intent(in) :: element                  !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)        !< vertex coordinates [length]
    procedure(body_force_fn) :: bf                  !< body force density
    real(wp), intent(inout) :: fe(2, MAX_NVERT)     !< nodal loads of the vertices, added to [force]
    !> .true.: per radian, the integrand weighted by r = x (a meridian section)
    logical, intent(in), optional :: axisymmetric
    real(wp), parameter :: q3(3) = [-0.774596669241483377035853079956_wp, 0.0_wp, &
                                     0.774596669241483377035853079956_wp]
    real(wp), parameter :: w3(3) = [5.0_wp/9.0_wp, 8.0_wp/9.0_wp, 5.0_wp/9.0_wp]
    real(wp), parameter :: bary(3, 3) = reshape([2.0_wp/3.0_wp, 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 2.0_wp/3.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, 2.0_wp/3.0_wp], [3, 3])
    integer :: a, ig, jg
    real(wp) :: nfun(4), g(2, MAX_NVERT), det, xq(2), bv(2)
    logical :: axi

    axi = .false.
    if (present(axisymmetric)) axi = axisymmetric
    if (element == ELEM_Q1) then
      do jg = 1, 3
        do ig = 1, 3
          call q1_gradients(xe, q3(ig), q3(jg), nfun, g, det)
          xq = matmul(xe, nfun)
          call bf(xq, bv)
          if (axi) bv = bv*xq(1)
          do a = 1, 4
            fe(:, a) = fe(:, a) + w3(ig)*w3(jg)*det*nfun(a)*bv
          end do
        end do
      end do
    else
      call p1_gradients(xe, g, det)
      do ig = 1, 3
        xq = matmul(xe(:, 1:3), bary(:, ig))
        call bf(xq, bv)
        if (axi) bv = bv*xq(1)
        do a = 1, 3
          ! weight area/3 = det/6
          fe(:, a) = fe(:, a) + (det/6.0_wp)*bary(a, ig)*bv
        end do
      end do
    end if
  end subroutine element_body_force

  !> w(a) = the integral of shape function a over the element: the consistent nodal load of
  !! a constant body force b is w(a) b. Q1: 2x2 Gauss, exact (N_a det J is of degree 2 in
  !! each reference coordinate); P1: a third of the area each. With `axisymmetric`, per radian
  !! int N_a r dA: Q1 the same points (N_a det J r of degree 3: exact), P1 A/12 (2 r_a + r_b +
  !! r_c), exact.
  pure subroutine element_shape_integrals(element, xe, w, axisymmetric)
    integer, intent(in) :: element                  !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)        !< vertex coordinates [length]
    real(wp), intent(out) :: w(MAX_NVERT)           !< [length^2], axisymmetric [length^3]
    logical, intent(in), optional :: axisymmetric   !< a meridian section (x = r): weighted by r
    integer :: ig, jg
    real(wp) :: nfun(4), g(2, MAX_NVERT), det
    logical :: axi
    axi = .false.
    if (present(axisymmetric)) axi = axisymmetric
    w = 0.0_wp
    if (element == ELEM_Q1) then
      do jg = -1, 1, 2
        do ig = -1, 1, 2
          call q1_gradients(xe, ig*gp2, jg*gp2, nfun, g, det)
          if (axi) then
            w = w + det*nfun*sum(nfun*xe(1, :))
          else
            w = w + det*nfun
          end if
        end do
      end do
    else
      call p1_gradients(xe, g, det)
      if (axi) then
        w(1) = det/24.0_wp*(2.0_wp*xe(1, 1) + xe(1, 2) + xe(1, 3))
        w(2) = det/24.0_wp*(xe(1, 1) + 2.0_wp*xe(1, 2) + xe(1, 3))
        w(3) = det/24.0_wp*(xe(1, 1) + xe(1, 2) + 2.0_wp*xe(1, 3))
      else
        w(1:3) = det/6.0_wp
      end if
    end if
  end subroutine element_shape_integrals

  !> Add the consistent nodal loads of a linear traction t(s) = t0 + t1 s on the straight
  !! edge from xa to xb to `fe`, s being coordinate `coord` of the point; 2-point Gauss
  !! (exact for a linear traction times linear shape functions).
  pure subroutine edge_traction(xa, xb, coord, t0, t1, fe, axisymmetric)
    real(wp), intent(in) :: xa(2)            !< first end of the edge [length]
    real(wp), intent(in) :: xb(2)            !< second end of the edge [length]
    integer, intent(in) :: coord             !< s is x (1) or y (2)
    real(wp), intent(in) :: t0(2)            !< traction at s = 0 [stress]
    real(wp), intent(in) :: t1(2)            !< traction slope d t / d s [stress/length]
    real(wp), intent(inout) :: fe(2, 2)      !< nodal loads of the two ends, added to [force]
    !> .true.: per radian, the integrand weighted by r = x (still exact: of degree 3)
    logical, intent(in), optional :: axisymmetric
    integer :: ig
    real(wp) :: len, xi, wa, wb, s, tv(2)
    logical :: axi

    axi = .false.
    if (present(axisymmetric)) axi = axisymmetric
    len = norm2(xb - xa)
    do ig = -1, 1, 2
      xi = ig*gp2
      wa = 0.5_wp*(1.0_wp - xi)
      wb = 0.5_wp*(1.0_wp + xi)
      s = wa*xa(coord) + wb*xb(coord)
      tv = t0 + t1*s
      if (axi) tv = tv*(wa*xa(1) + wb*xb(1))
      ! Gauss weight 1, Jacobian len/2.
      fe(:, 1) = fe(:, 1) + 0.5_wp*len*wa*tv
      fe(:, 2) = fe(:, 2) + 0.5_wp*len*wb*tv
    end do
  end subroutine edge_traction

  !> Stress of an element from its displacements: Q1 at the cell centre, P1 the constant
  !! value; cs = (sxx, syy, sxy, szz), szz = lambda (exx + eyy) = nu (sxx + syy) in plane
  !! strain and 0 in plane stress.
  pure subroutine element_stress(element, xe, ue, lame_lambda, lame_mu, plane_strain, cs)
    integer, intent(in) :: element               !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)     !< vertex coordinates [length]
    real(wp), intent(in) :: ue(MAX_NDOF)         !< element displacements, interleaved [length]
    real(wp), intent(in) :: lame_lambda          !< (effective) first Lame parameter [stress]
    real(wp), intent(in) :: lame_mu              !< shear modulus [stress]
    logical, intent(in) :: plane_strain          !< .true. plane strain, .false. plane stress
    real(wp), intent(out) :: cs(4)               !< sxx, syy, sxy, szz [stress]
    real(wp) :: g(2, MAX_NVERT), nfun(4), det, exx, eyy, gxy
    integer :: a

    if (element == ELEM_Q1) then
      call q1_gradients(xe, 0.0_wp, 0.0_wp, nfun, g, det)
    else
      call p1_gradients(xe, g, det)
    end if
    exx = 0.0_wp
    eyy = 0.0_wp
    gxy = 0.0_wp
    do a = 1, element_nvert(element)
      exx = exx + g(1, a)*ue(2*a - 1)
      eyy = eyy + g(2, a)*ue(2*a)
      gxy = gxy + g(2, a)*ue(2*a - 1) + g(1, a)*ue(2*a)
    end do
    cs(1) = (lame_lambda + 2.0_wp*lame_mu)*exx + lame_lambda*eyy
    cs(2) = lame_lambda*exx + (lame_lambda + 2.0_wp*lame_mu)*eyy
    cs(3) = lame_mu*gxy
    if (plane_strain) then
      cs(4) = lame_lambda*(exx + eyy)    ! = nu (sxx + syy)
    else
      cs(4) = 0.0_wp
    end if
  end subroutine element_stress

  !> Stress of an element of any plane stiffness d (config's elastic_law_t%d): Q1 at the cell
  !! centre, P1 the constant value; cs = (sxx, syy, sxy, szz) = d (exx, eyy, gxy, 0).
  pure subroutine element_stress_general(element, xe, ue, d, cs)
    integer, intent(in) :: element               !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)     !< vertex coordinates [length]
    real(wp), intent(in) :: ue(MAX_NDOF)         !< element displacements, interleaved [length]
    real(wp), intent(in) :: d(4, 4)              !< the stiffness [stress]
    real(wp), intent(out) :: cs(4)               !< sxx, syy, sxy, szz [stress]
    real(wp) :: g(2, MAX_NVERT), nfun(4), det, e(3)
    integer :: a
    if (element == ELEM_Q1) then
      call q1_gradients(xe, 0.0_wp, 0.0_wp, nfun, g, det)
    else
      call p1_gradients(xe, g, det)
    end if
    e = 0.0_wp
    do a = 1, element_nvert(element)
      e(1) = e(1) + g(1, a)*ue(2*a - 1)
      e(2) = e(2) + g(2, a)*ue(2*a)
      e(3) = e(3) + g(2, a)*ue(2*a - 1) + g(1, a)*ue(2*a)
    end do
    cs = matmul(d(:, 1:3), e)
  end subroutine element_stress_general

  ! ---------------------------------------------------------------------------------
  ! Axisymmetric bodies: x is the radius r >= 0, y the axis z; strains (err, ezz, grz, ett)
  ! with the hoop strain ett = ur/r; every integral per radian, weighted by r.
  ! ---------------------------------------------------------------------------------

  !> The quadrature points of an axisymmetric cell: Q1 2x2 Gauss; P1 the 3-point interior
  !! rule of degree 2 (the hoop term N/r is not a polynomial: a one-point rule would not
  !! pass the patch test of a uniform radial strain). np points, shape functions, gradients,
  !! radius and weight (det J times the reference weight; r not included).
  pure subroutine axi_points(element, xe, np, nf, g, r, w, minjac)
    integer, intent(in) :: element
    real(wp), intent(in) :: xe(2, MAX_NVERT)
    integer, intent(out) :: np
    real(wp), intent(out) :: nf(4, 4), g(2, MAX_NVERT, 4), r(4), w(4), minjac
    real(wp), parameter :: bary(3, 3) = reshape([2.0_wp/3.0_wp, 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 2.0_wp/3.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, 2.0_wp/3.0_wp], [3, 3])
    real(wp) :: det, gg(2, MAX_NVERT)
    integer :: q, ig, jg
    nf = 0.0_wp
    g = 0.0_wp
    if (element == ELEM_Q1) then
      np = 4
      minjac = huge(1.0_wp)
      q = 0
      do jg = -1, 1, 2
        do ig = -1, 1, 2
          q = q + 1
          call q1_gradients(xe, ig*gp2, jg*gp2, nf(:, q), g(:, :, q), det)
          minjac = min(minjac, det)
          w(q) = max(det, 0.0_wp)
          r(q) = sum(nf(:, q)*xe(1, :))
        end do
      end do
    else
      np = 3
      call p1_gradients(xe, gg, det)
      minjac = det
      do q = 1, 3
        nf(1:3, q) = bary(:, q)
        g(:, :, q) = gg
        w(q) = max(det, 0.0_wp)/6.0_wp
        r(q) = sum(bary(:, q)*xe(1, 1:3))
      end do
    end if
  end subroutine axi_points

  !> Axisymmetric element stiffness per radian, int B' d B r dA, d the 4x4 stiffness of
  !! (err, ezz, grz, ett); B of vertex a: [gr 0; 0 gz; gz gr; N/r 0]. minjac as
  !! element_stiffness.
  pure subroutine axi_stiffness(element, xe, d, ke, minjac)
    integer, intent(in) :: element                   !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)         !< vertex coordinates (r, z) [length]
    real(wp), intent(in) :: d(4, 4)                  !< the stiffness [stress]
    real(wp), intent(out) :: ke(MAX_NDOF, MAX_NDOF)  !< [stress x length]
    real(wp), intent(out) :: minjac                  !< smallest Jacobian determinant [length^2]
    real(wp) :: nf(4, 4), g(2, MAX_NVERT, 4), r(4), w(4), bm(4, MAX_NDOF), db(4, MAX_NDOF)
    integer :: np, q, a, nv
    ke = 0.0_wp
    call axi_points(element, xe, np, nf, g, r, w, minjac)
    if (.not. minjac > 0.0_wp) return
    nv = element_nvert(element)
    do q = 1, np
      bm = 0.0_wp
      do a = 1, nv
        bm(1, 2*a - 1) = g(1, a, q)
        bm(2, 2*a) = g(2, a, q)
        bm(3, 2*a - 1) = g(2, a, q)
        bm(3, 2*a) = g(1, a, q)
        bm(4, 2*a - 1) = nf(a, q)/r(q)
      end do
      db(:, 1:2*nv) = matmul(d, bm(:, 1:2*nv))
      ke(1:2*nv, 1:2*nv) = ke(1:2*nv, 1:2*nv) + (w(q)*r(q))*matmul(transpose(bm(:, 1:2*nv)), db(:, 1:2*nv))
    end do
    ke(1:2*nv, 1:2*nv) = 0.5_wp*(ke(1:2*nv, 1:2*nv) + transpose(ke(1:2*nv, 1:2*nv)))
  end subroutine axi_stiffness

  !> The stress of an axisymmetric element at its centre (Q1) or centroid (P1):
  !! cs = (srr, szz, srz, stt) = d (err, ezz, grz, ett).
  pure subroutine axi_stress(element, xe, ue, d, cs)
    integer, intent(in) :: element               !< ELEM_Q1 or ELEM_P1
    real(wp), intent(in) :: xe(2, MAX_NVERT)     !< vertex coordinates (r, z) [length]
    real(wp), intent(in) :: ue(MAX_NDOF)         !< element displacements (ur, uz) interleaved [length]
    real(wp), intent(in) :: d(4, 4)              !< the stiffness [stress]
    real(wp), intent(out) :: cs(4)               !< srr, szz, srz, stt [stress]
    real(wp) :: g(2, MAX_NVERT), nfun(4), det, e(4), rc
    integer :: a, nv
    nv = element_nvert(element)
    if (element == ELEM_Q1) then
      call q1_gradients(xe, 0.0_wp, 0.0_wp, nfun, g, det)
    else
      call p1_gradients(xe, g, det)
      nfun = [1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp]/3.0_wp
    end if
    rc = sum(nfun(1:nv)*xe(1, 1:nv))
    e = 0.0_wp
    do a = 1, nv
      e(1) = e(1) + g(1, a)*ue(2*a - 1)
      e(2) = e(2) + g(2, a)*ue(2*a)
      e(3) = e(3) + g(2, a)*ue(2*a - 1) + g(1, a)*ue(2*a)
      e(4) = e(4) + nfun(a)*ue(2*a - 1)
    end do
    e(4) = e(4)/rc
    cs = matmul(d, e)
  end subroutine axi_stress

end module elements
