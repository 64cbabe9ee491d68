!> Element kernels of 3D linear elasticity: shape functions and their gradients, element
!! stiffness, element stress, the nodal weights of a constant body force and the nodal
!! loads of a constant face traction, for the trilinear hexahedron (HEX8, 2x2x2 Gauss) and
!! the linear tetrahedron (TET4, exact); and the split of a structured grid's hexahedral
!! cell into six tetrahedra.
!!
!! Vertex orders are Gmsh's. HEX8: reference vertices (-1,-1,-1), (1,-1,-1), (1,1,-1),
!! (-1,1,-1), then the same at zeta = +1. TET4: (0,0,0), (1,0,0), (0,1,0), (0,0,1), positive
!! when (x2 - x1, x3 - x1, x4 - x1) is right-handed. Every kernel takes the vertex
!! coordinates `xe(3, HEX8_NVERT)` (a TET4 uses the first 4 columns), never mesh indices.
!! Element DOFs are interleaved: vertex a, component c (1 = x, 2 = y, 3 = z) is local dof
!! 3 (a - 1) + c. Strains and stresses in Voigt order (xx, yy, zz, yz, xz, xy), the shear
!! strains engineering ones (gyz = 2 eyz); the material is any symmetric 6x6 stiffness d.
!! Units are the deck's, consistently: [length], [stress] = [force]/[length]^2.
module elements_3d
  use kinds, only: wp
  implicit none (type, external)
  private

  public :: hex8_gradients, tet4_gradients, isotropic_d3, solid_stiffness, solid_stress
  public :: solid_shape_integrals, face_traction, face_area_normal, kuhn_tets

  integer, parameter, public :: SOLID_NDIM = 3                       !< coordinates and displacement components of a node
  integer, parameter, public :: NVOIGT = 6                           !< strain and stress components (xx, yy, zz, yz, xz, xy)
  integer, parameter, public :: HEX8_NVERT = 8                       !< vertices of the hexahedron
  integer, parameter, public :: TET4_NVERT = 4                       !< vertices of the tetrahedron
  integer, parameter, public :: SOLID_MAX_NDOF = SOLID_NDIM*HEX8_NVERT   !< most DOFs of a solid element (HEX8)
  integer, parameter, public :: FACE_MAX_NVERT = 4                   !< most vertices of a face (quadrilateral)
  integer, parameter, public :: KUHN_NTET = 6                        !< tetrahedra of kuhn_tets's split

  ! reference vertices of HEX8 (Gmsh order)
  real(wp), parameter :: xa_h(HEX8_NVERT) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: ea_h(HEX8_NVERT) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: za_h(HEX8_NVERT) = [-1.0_wp, -1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp]
  ! reference vertices of a quadrilateral face
  real(wp), parameter :: xa_f(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: ea_f(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]
  real(wp), parameter :: gp2 = 0.577350269189625764509148780502_wp      ! 1/sqrt(3), 2-point Gauss
  ! reference gradients of TET4's shape functions 1 - r - s - t, r, s, t
  real(wp), parameter :: dn_t(SOLID_NDIM, TET4_NVERT) = reshape([-1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, &
                                                                 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], &
                                                                [SOLID_NDIM, TET4_NVERT])

contains

  !> Trilinear shape functions of the hexahedron and their x, y, z gradients at the
  !! reference point (xi, eta, zeta) in [-1,1]^3. Where the Jacobian is not positive, g = 0.
  pure subroutine hex8_gradients(xe, xi, eta, zeta, nfun, g, det)
    real(wp), intent(in) :: xe(SOLID_NDIM, HEX8_NVERT)    !< vertex coordinates [length]
    real(wp), intent(in) :: xi                            !< reference coordinate xi [-]
    real(wp), intent(in) :: eta                           !< reference coordinate eta [-]
    real(wp), intent(in) :: zeta                          !< reference coordinate zeta [-]
    real(wp), intent(out) :: nfun(HEX8_NVERT)             !< shape functions [-]
    real(wp), intent(out) :: g(SOLID_NDIM, HEX8_NVERT)    !< (d/dx, d/dy, d/dz) of each shape function [1/length]
    real(wp), intent(out) :: det                          !< Jacobian determinant [length^3]
    real(wp) :: dn(SOLID_NDIM, HEX8_NVERT), jm(SOLID_NDIM, SOLID_NDIM), ji(SOLID_NDIM, SOLID_NDIM)
    real(wp) :: fx, fe, fz
    integer :: a
    do a = 1, HEX8_NVERT
      fx = 1.0_wp + xi*xa_h(a)
      fe = 1.0_wp + eta*ea_h(a)
      fz = 1.0_wp + zeta*za_h(a)
      nfun(a) = 0.125_wp*fx*fe*fz
      dn(1, a) = 0.125_wp*xa_h(a)*fe*fz
      dn(2, a) = 0.125_wp*ea_h(a)*fx*fz
      dn(3, a) = 0.125_wp*za_h(a)*fx*fe
    end do
    jm = matmul(dn, transpose(xe))      ! jm(i, j) = d x_j / d xi_i
    call jacobian_inverse(jm, det, ji)
    if (det > 0.0_wp) then
      g = matmul(ji, dn)
    else
      g = 0.0_wp
    end if
  end subroutine hex8_gradients

  !> Constant gradients of the linear tetrahedron's shape functions. Where the tetrahedron
  !! is not positively oriented (det <= 0), g = 0.
  pure subroutine tet4_gradients(xe, g, det)
    real(wp), intent(in) :: xe(SOLID_NDIM, TET4_NVERT)    !< vertex coordinates [length]
    real(wp), intent(out) :: g(SOLID_NDIM, TET4_NVERT)    !< (d/dx, d/dy, d/dz) of each shape function [1/length]
    real(wp), intent(out) :: det                          !< 6 times the signed volume [length^3]
    real(wp) :: jm(SOLID_NDIM, SOLID_NDIM), ji(SOLID_NDIM, SOLID_NDIM)
    integer :: i
    do i = 1, SOLID_NDIM
      jm(i, :) = xe(:, i + 1) - xe(:, 1)
    end do
    call jacobian_inverse(jm, det, ji)
    if (det > 0.0_wp) then
      g = matmul(ji, dn_t)
    else
      g = 0.0_wp
    end if
  end subroutine tet4_gradients

  !> The determinant of a 3x3 Jacobian and, where it is positive, its inverse (the adjugate
  !! over the determinant; ji = 0 otherwise).
  pure subroutine jacobian_inverse(jm, det, ji)
    real(wp), intent(in) :: jm(SOLID_NDIM, SOLID_NDIM)    !< the Jacobian [length]
    real(wp), intent(out) :: det                          !< its determinant [length^3]
    real(wp), intent(out) :: ji(SOLID_NDIM, SOLID_NDIM)   !< its inverse [1/length]
    ji(1, 1) = jm(2, 2)*jm(3, 3) - jm(2, 3)*jm(3, 2)
    ji(1, 2) = jm(1, 3)*jm(3, 2) - jm(1, 2)*jm(3, 3)
    ji(1, 3) = jm(1, 2)*jm(2, 3) - jm(1, 3)*jm(2, 2)
    ji(2, 1) = jm(2, 3)*jm(3, 1) - jm(2, 1)*jm(3, 3)
    ji(2, 2) = jm(1, 1)*jm(3, 3) - jm(1, 3)*jm(3, 1)
    ji(2, 3) = jm(1, 3)*jm(2, 1) - jm(1, 1)*jm(2, 3)
    ji(3, 1) = jm(2, 1)*jm(3, 2) - jm(2, 2)*jm(3, 1)
    ji(3, 2) = jm(1, 2)*jm(3, 1) - jm(1, 1)*jm(3, 2)
    ji(3, 3) = jm(1, 1)*jm(2, 2) - jm(1, 2)*jm(2, 1)
    det = jm(1, 1)*ji(1, 1) + jm(1, 2)*ji(2, 1) + jm(1, 3)*ji(3, 1)
    if (det > 0.0_wp) then
      ji = ji/det
    else
      ji = 0.0_wp
    end if
  end subroutine jacobian_inverse

  !> The isotropic stiffness in Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear
  !! strains: lambda + 2 mu on the normal diagonal, lambda off it, mu on the shear diagonal.
  pure subroutine isotropic_d3(lame_lambda, lame_mu, d)
    real(wp), intent(in) :: lame_lambda               !< first Lame parameter [stress]
    real(wp), intent(in) :: lame_mu                   !< shear modulus [stress]
    real(wp), intent(out) :: d(NVOIGT, NVOIGT)        !< the stiffness [stress]
    integer :: i
    d = 0.0_wp
    d(1:3, 1:3) = lame_lambda
    do i = 1, 3
      d(i, i) = lame_lambda + 2.0_wp*lame_mu
      d(i + 3, i + 3) = lame_mu
    end do
  end subroutine isotropic_d3

  !> Add w B_a' D B_b to the blocks a <= b of ke for the gradients g of nv shape functions;
  !! B of vertex a maps (ux, uy, uz) to the Voigt strain: [gx 0 0; 0 gy 0; 0 0 gz; 0 gz gy;
  !! gz 0 gx; gy gx 0]. The blocks below the diagonal are left to the caller (symmetry).
  pure subroutine add_btdb3(nv, g, w, d, ke)
    integer, intent(in) :: nv
    real(wp), intent(in) :: g(SOLID_NDIM, HEX8_NVERT), w, d(NVOIGT, NVOIGT)
    real(wp), intent(inout) :: ke(SOLID_MAX_NDOF, SOLID_MAX_NDOF)
    real(wp) :: db(NVOIGT, SOLID_NDIM), gx, gy, gz
    integer :: a, b, c, ib
    do b = 1, nv
      gx = g(1, b)*w
      gy = g(2, b)*w
      gz = g(3, b)*w
      db(:, 1) = d(:, 1)*gx + d(:, 5)*gz + d(:, 6)*gy     ! w D B_b, its ux, uy, uz columns
      db(:, 2) = d(:, 2)*gy + d(:, 4)*gz + d(:, 6)*gx
      db(:, 3) = d(:, 3)*gz + d(:, 4)*gy + d(:, 5)*gx
      do c = 1, SOLID_NDIM
        ib = SOLID_NDIM*(b - 1) + c
        do a = 1, b
          ke(3*a - 2, ib) = ke(3*a - 2, ib) + g(1, a)*db(1, c) + g(3, a)*db(5, c) + g(2, a)*db(6, c)
          ke(3*a - 1, ib) = ke(3*a - 1, ib) + g(2, a)*db(2, c) + g(3, a)*db(4, c) + g(1, a)*db(6, c)
          ke(3*a, ib) = ke(3*a, ib) + g(3, a)*db(3, c) + g(2, a)*db(4, c) + g(1, a)*db(5, c)
        end do
      end do
    end do
  end subroutine add_btdb3

  !> Element stiffness int B' D B dV: HEX8 (nv = 8) by 2x2x2 Gauss, TET4 (nv = 4, the first
  !! 4 columns of xe) exactly, its leading 12x12 block filled and the rest 0; exactly
  !! symmetric. minjac = the smallest Jacobian determinant met (HEX8: at the Gauss points;
  !! TET4: 6 times the signed volume), not positive for an inverted or degenerate element,
  !! which the caller refuses (a point where it is not positive adds nothing). Another nv:
  !! ke = 0 and minjac = 0.
  pure subroutine solid_stiffness(nv, xe, d, ke, minjac)
    integer, intent(in) :: nv                                        !< HEX8_NVERT or TET4_NVERT
    real(wp), intent(in) :: xe(SOLID_NDIM, HEX8_NVERT)               !< vertex coordinates [length]
    real(wp), intent(in) :: d(NVOIGT, NVOIGT)                        !< the stiffness, symmetric [stress]
    real(wp), intent(out) :: ke(SOLID_MAX_NDOF, SOLID_MAX_NDOF)      !< element stiffness [stress x length]
    real(wp), intent(out) :: minjac                                  !< smallest Jacobian determinant [length^3]
    real(wp) :: nfun(HEX8_NVERT), g(SOLID_NDIM, HEX8_NVERT), det
    integer :: i, j, k, i2
    ke = 0.0_wp
    g = 0.0_wp
    if (nv == HEX8_NVERT) then
      minjac = huge(1.0_wp)
      do k = -1, 1, 2
        do j = -1, 1, 2
          do i = -1, 1, 2
            call hex8_gradients(xe, i*gp2, j*gp2, k*gp2, nfun, g, det)
            minjac = min(minjac, det)
            if (det > 0.0_wp) call add_btdb3(HEX8_NVERT, g, det, d, ke)    ! Gauss weights 1
          end do
        end do
      end do
    else if (nv == TET4_NVERT) then
      call tet4_gradients(xe(:, 1:TET4_NVERT), g(:, 1:TET4_NVERT), det)
      minjac = det
      if (det > 0.0_wp) call add_btdb3(TET4_NVERT, g, det/6.0_wp, d, ke)
    else
      minjac = 0.0_wp
      return
    end if
    do j = 1, SOLID_NDIM*nv
      do i2 = j + 1, SOLID_NDIM*nv
        ke(i2, j) = ke(j, i2)
      end do
    end do
  end subroutine solid_stiffness

  !> The Voigt strain B ue of an element from its gradients g.
  pure subroutine strain_of(nv, g, ue, e)
    integer, intent(in) :: nv
    real(wp), intent(in) :: g(SOLID_NDIM, HEX8_NVERT), ue(SOLID_MAX_NDOF)
    real(wp), intent(out) :: e(NVOIGT)
    real(wp) :: ux, uy, uz
    integer :: a
    e = 0.0_wp
    do a = 1, nv
      ux = ue(3*a - 2)
      uy = ue(3*a - 1)
      uz = ue(3*a)
      e(1) = e(1) + g(1, a)*ux
      e(2) = e(2) + g(2, a)*uy
      e(3) = e(3) + g(3, a)*uz
      e(4) = e(4) + g(3, a)*uy + g(2, a)*uz
      e(5) = e(5) + g(3, a)*ux + g(1, a)*uz
      e(6) = e(6) + g(2, a)*ux + g(1, a)*uy
    end do
  end subroutine strain_of

  !> The stress d B ue of an element at its centroid: HEX8 at the reference centre, TET4
  !! the constant value; 0 where the element is inverted there. Another nv: s = 0.
  pure subroutine solid_stress(nv, xe, ue, d, s)
    integer, intent(in) :: nv                                  !< HEX8_NVERT or TET4_NVERT
    real(wp), intent(in) :: xe(SOLID_NDIM, HEX8_NVERT)         !< vertex coordinates [length]
    real(wp), intent(in) :: ue(SOLID_MAX_NDOF)                 !< element displacements, interleaved [length]
    real(wp), intent(in) :: d(NVOIGT, NVOIGT)                  !< the stiffness [stress]
    real(wp), intent(out) :: s(NVOIGT)                         !< sxx, syy, szz, syz, sxz, sxy [stress]
    real(wp) :: nfun(HEX8_NVERT), g(SOLID_NDIM, HEX8_NVERT), det, e(NVOIGT)
    g = 0.0_wp
    if (nv == HEX8_NVERT) then
      call hex8_gradients(xe, 0.0_wp, 0.0_wp, 0.0_wp, nfun, g, det)
    else if (nv == TET4_NVERT) then
      call tet4_gradients(xe(:, 1:TET4_NVERT), g(:, 1:TET4_NVERT), det)
    else
      s = 0.0_wp
      return
    end if
    call strain_of(nv, g, ue, e)
    s = matmul(d, e)
  end subroutine solid_stress

  !> w(a) = the integral of shape function a over the element, so the consistent nodal load
  !! of a constant body force b is w(a) b. HEX8: 2x2x2 Gauss, exact (N_a det J is of degree 3
  !! in each reference coordinate); TET4: a quarter of the volume each, w(5:8) = 0. Signed:
  !! an inverted element gives negative weights. Another nv: w = 0.
  pure subroutine solid_shape_integrals(nv, xe, w)
    integer, intent(in) :: nv                               !< HEX8_NVERT or TET4_NVERT
    real(wp), intent(in) :: xe(SOLID_NDIM, HEX8_NVERT)      !< vertex coordinates [length]
    real(wp), intent(out) :: w(HEX8_NVERT)                  !< [length^3]
    real(wp) :: nfun(HEX8_NVERT), g(SOLID_NDIM, HEX8_NVERT), det
    integer :: i, j, k
    w = 0.0_wp
    if (nv == HEX8_NVERT) then
      do k = -1, 1, 2
        do j = -1, 1, 2
          do i = -1, 1, 2
            call hex8_gradients(xe, i*gp2, j*gp2, k*gp2, nfun, g, det)
            w = w + det*nfun
          end do
        end do
      end do
    else if (nv == TET4_NVERT) then
      call tet4_gradients(xe(:, 1:TET4_NVERT), g(:, 1:TET4_NVERT), det)
      w(1:TET4_NVERT) = det/24.0_wp
    end if
  end subroutine solid_shape_integrals

  !> The cross product a x b.
  pure function cross(a, b) result(c)
    real(wp), intent(in) :: a(SOLID_NDIM), b(SOLID_NDIM)
    real(wp) :: c(SOLID_NDIM)
    c(1) = a(2)*b(3) - a(3)*b(2)
    c(2) = a(3)*b(1) - a(1)*b(3)
    c(3) = a(1)*b(2) - a(2)*b(1)
  end function cross

  !> The consistent nodal loads int N_a t dA of a constant traction t on a face: a linear
  !! triangle (nv = 3: area/3 each) or a bilinear quadrilateral (nv = 4: 2x2 Gauss on the
  !! surface Jacobian |dx/dxi x dx/deta|, exact on a planar face). Columns beyond nv are 0;
  !! another nv: fe = 0.
  pure subroutine face_traction(nv, xf, t, fe)
    integer, intent(in) :: nv                                    !< 3 (triangle) or 4 (quadrilateral)
    real(wp), intent(in) :: xf(SOLID_NDIM, FACE_MAX_NVERT)       !< vertex coordinates [length]
    real(wp), intent(in) :: t(SOLID_NDIM)                        !< the traction [stress]
    real(wp), intent(out) :: fe(SOLID_NDIM, FACE_MAX_NVERT)      !< nodal loads of the vertices [force]
    real(wp) :: xi, eta, nf(4), dxi(4), deta(4), jac, area
    integer :: i, j, a
    fe = 0.0_wp
    if (nv == 3) then
      area = 0.5_wp*norm2(cross(xf(:, 2) - xf(:, 1), xf(:, 3) - xf(:, 1)))
      do a = 1, 3
        fe(:, a) = t*(area/3.0_wp)
      end do
    else if (nv == 4) then
      do j = -1, 1, 2
        do i = -1, 1, 2
          xi = i*gp2
          eta = j*gp2
          do a = 1, 4
            nf(a) = 0.25_wp*(1.0_wp + xi*xa_f(a))*(1.0_wp + eta*ea_f(a))
            dxi(a) = 0.25_wp*xa_f(a)*(1.0_wp + eta*ea_f(a))
            deta(a) = 0.25_wp*ea_f(a)*(1.0_wp + xi*xa_f(a))
          end do
          jac = norm2(cross(matmul(xf, dxi), matmul(xf, deta)))
          do a = 1, 4
            fe(:, a) = fe(:, a) + (nf(a)*jac)*t      ! Gauss weights 1
          end do
        end do
      end do
    end if
  end subroutine face_traction

  !> The area-weighted normal int n dA of a face, by the right-hand rule over its vertex
  !! order: a triangle (x2 - x1) x (x3 - x1)/2, a quadrilateral (x3 - x1) x (x4 - x2)/2 (the
  !! bilinear surface's, exact also where it is not planar). Another nv: an = 0.
  pure subroutine face_area_normal(nv, xf, an)
    integer, intent(in) :: nv                                    !< 3 (triangle) or 4 (quadrilateral)
    real(wp), intent(in) :: xf(SOLID_NDIM, FACE_MAX_NVERT)       !< vertex coordinates [length]
    real(wp), intent(out) :: an(SOLID_NDIM)                      !< area times the unit normal [length^2]
    if (nv == 3) then
      an = 0.5_wp*cross(xf(:, 2) - xf(:, 1), xf(:, 3) - xf(:, 1))
    else if (nv == 4) then
      an = 0.5_wp*cross(xf(:, 3) - xf(:, 1), xf(:, 4) - xf(:, 2))
    else
      an = 0.0_wp
    end if
  end subroutine face_area_normal

  !> A hexahedral grid cell's 8 vertex ids (HEX8 order) split into 6 tetrahedra (TET4 order,
  !! positively oriented when the cell is) sharing the diagonal v1-v7: the Kuhn (Freudenthal)
  !! split, one tetrahedron per order in which a monotone path from v1 to v7 along the cell's
  !! edges takes the three directions (v1 -> v2 is +xi, v1 -> v4 +eta, v1 -> v5 +zeta). Every
  !! face of the cell is cut by its diagonal from its lowest corner to its highest in (xi,
  !! eta, zeta) (v1-v8, v2-v7, v1-v6, v4-v7, v1-v3, v5-v7), so two cells of a structured grid
  !! whose local axes are the grid's cut their shared face alike: the tetrahedra conform
  !! without the alternation a split about another diagonal needs. Cells whose local axes
  !! differ (an unstructured hexahedral mesh) need not conform.
  pure subroutine kuhn_tets(v, tets)
    integer, intent(in) :: v(HEX8_NVERT)                  !< the cell's vertex ids, HEX8 order
    integer, intent(out) :: tets(TET4_NVERT, KUHN_NTET)   !< the tetrahedra's vertex ids
    ! the paths xi eta zeta, eta zeta xi, zeta xi eta (even: in path order), and xi zeta eta,
    ! eta xi zeta, zeta eta xi (odd: the two middle vertices swapped to keep the orientation)
    integer, parameter :: local(TET4_NVERT, KUHN_NTET) = reshape([1, 2, 3, 7, 1, 4, 8, 7, 1, 5, 6, 7, &
                                                                  1, 6, 2, 7, 1, 3, 4, 7, 1, 8, 5, 7], &
                                                                 [TET4_NVERT, KUHN_NTET])
    tets = reshape(v(reshape(local, [TET4_NVERT*KUHN_NTET])), [TET4_NVERT, KUHN_NTET])
  end subroutine kuhn_tets

end module elements_3d
