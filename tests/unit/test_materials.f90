!> Unit tests of the materials (module material_laws and the assembly's general kernel):
!!  - the patch test of orthotropic and anisotropic materials turned by 0, 30 and 90 degrees,
!!    in plane strain and plane stress, on distorted Q1 and P1 meshes: a uniform stress sigma
!!    is chosen, its strain computed here independently (the stress turned into the material
!!    axes as a tensor, the compliance of the engineering constants applied there, or the 3x3
!!    stiffness inverted by Cramer's rule, and the strain turned back as a tensor), the linear
!!    displacement of that strain prescribed on the boundary: the interior nodes reproduce it
!!    and the nodal stresses are sigma (szz too), to rounding;
!!  - the isotropic law of young and poisson is the Lame kernel's, entry for entry;
!!  - a turn by 90 degrees swaps the axes: d(1,1) of the turned law is the unturned d(2,2);
!!  - the eigenvalues of the Jacobi routine against a matrix of known spectrum;
!!  - bad materials: Poisson's ratios beyond positive definiteness, a stiffness with a
!!    negative eigenvalue (named in the message), plane strain without e3.
program test_materials
  use kinds, only: wp
  use config, only: body_cfg_t, traction_cfg_t, material_cfg_t, elastic_law_t, ELEM_Q1, ELEM_P1, &
                    BC_DISPLACEMENT, MAT_ORTHOTROPIC, MAT_ANISOTROPIC, MAT_ISOTROPIC, UNSET
  use mesh, only: mesh_t
  use assembly, only: body_system_t, assemble_body, nodal_stress, lame_parameters
  use material_laws, only: material_law, symmetric_eigenvalues
  use testing, only: grid_mesh, report, test_summary, solve_full, error_parts
  use errors, only: error_t
  implicit none (type, external)

  real(wp), parameter :: PI = acos(-1.0_wp)
  integer :: ia, ip, kind_k, el
  real(wp), parameter :: angles(3) = [0.0_wp, 30.0_wp, 90.0_wp]

  do kind_k = 1, 2
    do ip = 1, 2
      do ia = 1, 3
        do el = 1, 2
          call patch(kind_k, ip == 1, angles(ia), merge(ELEM_Q1, ELEM_P1, el == 1))
        end do
      end do
    end do
  end do
  call isotropic_same()
  call turn_swaps()
  call eigen_known()
  call bad_materials()
  call test_summary()

contains

  function ortho() result(m)
    type(material_cfg_t) :: m
    m%kind = MAT_ORTHOTROPIC
    m%e1 = 140.0_wp
    m%e2 = 10.0_wp
    m%e3 = 12.0_wp
    m%nu12 = 0.3_wp
    m%nu13 = 0.28_wp
    m%nu23 = 0.45_wp
    m%g12 = 5.0_wp
  end function ortho

  function aniso() result(m)
    type(material_cfg_t) :: m
    m%kind = MAT_ANISOTROPIC
    m%c11 = 200.0_wp
    m%c12 = 60.0_wp
    m%c16 = 25.0_wp
    m%c22 = 120.0_wp
    m%c26 = -15.0_wp
    m%c66 = 50.0_wp
    m%c13 = 55.0_wp
    m%c23 = 40.0_wp
    m%c36 = 7.0_wp
    m%c33 = 150.0_wp
  end function aniso

  !> The strain tensor (exx, eyy, gxy) and szz of the uniform stress s = (sxx, syy, sxy) in
  !! material m turned by `angle`, computed as tensors (independent of material_law).
  subroutine strain_of(m, plane_strain, angle, s, e, szz)
    type(material_cfg_t), intent(in) :: m
    logical, intent(in) :: plane_strain
    real(wp), intent(in) :: angle, s(3)
    real(wp), intent(out) :: e(3), szz
    real(wp) :: r(2, 2), sg(2, 2), sm(2, 2), em(2, 2), eg(2, 2), s33, c3(3, 3), v(3), c4(4, 4)
    real(wp) :: s11, s22, s12, s13, s23, s33c
    r(1, :) = [cos(angle*PI/180.0_wp), sin(angle*PI/180.0_wp)]    ! rows: the material axes
    r(2, :) = [-sin(angle*PI/180.0_wp), cos(angle*PI/180.0_wp)]
    sg = reshape([s(1), s(3), s(3), s(2)], [2, 2])
    sm = matmul(r, matmul(sg, transpose(r)))
    if (m%kind == MAT_ORTHOTROPIC) then
      s11 = 1/m%e1
      s22 = 1/m%e2
      s12 = -m%nu12/m%e1
      s13 = -m%nu13/m%e1
      s23 = -m%nu23/m%e2
      s33c = 1/m%e3
      s33 = 0.0_wp
      if (plane_strain) s33 = -(s13*sm(1, 1) + s23*sm(2, 2))/s33c     ! e33 = 0
      em(1, 1) = s11*sm(1, 1) + s12*sm(2, 2) + s13*s33
      em(2, 2) = s12*sm(1, 1) + s22*sm(2, 2) + s23*s33
      em(1, 2) = 0.5_wp*sm(1, 2)/m%g12
      em(2, 1) = em(1, 2)
      szz = s33
    else
      if (plane_strain) then
        c3 = reshape([m%c11, m%c12, m%c16, m%c12, m%c22, m%c26, m%c16, m%c26, m%c66], [3, 3])
      else     ! condense zz out by hand: szz = 0 gives ezz = -(c13 e1 + c23 e2 + c36 g)/c33
        c4 = 0.0_wp
        c4(1:3, 1:3) = reshape([m%c11, m%c12, m%c16, m%c12, m%c22, m%c26, m%c16, m%c26, m%c66], [3, 3])
        c4(4, 1:3) = [m%c13, m%c23, m%c36]
        c3 = c4(1:3, 1:3)
        c3(1, :) = c3(1, :) - c4(4, 1)*c4(4, 1:3)/m%c33
        c3(2, :) = c3(2, :) - c4(4, 2)*c4(4, 1:3)/m%c33
        c3(3, :) = c3(3, :) - c4(4, 3)*c4(4, 1:3)/m%c33
      end if
      v = cramer(c3, [sm(1, 1), sm(2, 2), sm(1, 2)])
      em = reshape([v(1), 0.5_wp*v(3), 0.5_wp*v(3), v(2)], [2, 2])
      szz = 0.0_wp
      if (plane_strain) szz = m%c13*v(1) + m%c23*v(2) + m%c36*v(3)
    end if
    eg = matmul(transpose(r), matmul(em, r))
    e = [eg(1, 1), eg(2, 2), 2*eg(1, 2)]
  end subroutine strain_of

  function cramer(a, b) result(x)
    real(wp), intent(in) :: a(3, 3), b(3)
    real(wp) :: x(3), t(3, 3), d
    integer :: k
    d = det3(a)
    do k = 1, 3
      t = a
      t(:, k) = b
      x(k) = det3(t)/d
    end do
  end function cramer

  pure real(wp) function det3(a)
    real(wp), intent(in) :: a(3, 3)
    det3 = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) &
           + a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
  end function det3

  subroutine patch(kind_k, plane_strain, angle, element)
    integer, intent(in) :: kind_k, element
    logical, intent(in) :: plane_strain
    real(wp), intent(in) :: angle
    type(material_cfg_t) :: m
    type(body_cfg_t) :: body
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    type(error_t) :: err
    real(wp), allocatable :: up(:), u(:), sigma(:, :), vm(:)
    real(wp) :: s(3), e(3), szz, worst, sworst, umax, h
    type(error_t) :: merr
    character(len=80) :: what
    character(len=256) :: emsg
    integer :: k, info

    if (kind_k == 1) then
      m = ortho()
    else
      m = aniso()
    end if
    write (what, '(a,a,a,f4.0,a,a)') merge('orthotropic', 'anisotropic', kind_k == 1), ' ', &
      merge('plane strain', 'plane stress', plane_strain), angle, ' deg ', merge('Q1', 'P1', element == ELEM_Q1)
    body%id = 1
    body%x0 = 0.3_wp
    body%y0 = -0.2_wp
    body%width = 1.3_wp
    body%height = 0.9_wp
    body%nx = 5
    body%ny = 4
    body%element = element
    body%bc = BC_DISPLACEMENT
    allocate (body%law(1))
    call material_law(m, angle, plane_strain, body%law(1), merr)
    call report(.not. merr%failed(), trim(what)//': material_law accepts the material')
    call grid_mesh(msh, body)
    h = 0.3_wp*body%width/body%nx                 ! distort the interior nodes
    do k = 1, msh%nnode
      if (abs(msh%xy(1, k) - body%x0) > 1e-9_wp .and. abs(msh%xy(1, k) - body%x0 - body%width) > 1e-9_wp .and. &
          abs(msh%xy(2, k) - body%y0) > 1e-9_wp .and. abs(msh%xy(2, k) - body%y0 - body%height) > 1e-9_wp) then
        msh%xy(1, k) = msh%xy(1, k) + h*sin(3.7_wp*k)
        msh%xy(2, k) = msh%xy(2, k) + h*cos(5.1_wp*k)
      end if
    end do
    s = [1.3_wp, -0.7_wp, 0.45_wp]
    call strain_of(m, plane_strain, angle, s, e, szz)
    allocate (up(2*msh%nnode))
    do k = 1, msh%nnode     ! u = (exx x + gxy/2 y, gxy/2 x + eyy y) + a rigid motion
      up(2*k - 1) = 0.01_wp + e(1)*msh%xy(1, k) + (0.5_wp*e(3) - 0.002_wp)*msh%xy(2, k)
      up(2*k) = -0.02_wp + (0.5_wp*e(3) + 0.002_wp)*msh%xy(1, k) + e(2)*msh%xy(2, k)
    end do
    call assemble_body(msh, body, plane_strain, tr, 0, sys, err, u_prescribed=up)
    call error_parts(err, info, emsg)
    call solve_full(sys, info, emsg, 'assemble_body', u)
    umax = maxval(abs(up))
    worst = maxval(abs(u - up))/umax
    call report(worst <= 1.0e-12_wp, trim(what)//': interior displacements exact (rel)', worst, 1.0e-12_wp)
    allocate (sigma(4, msh%nnode), vm(msh%nnode))
    call nodal_stress(msh, body, plane_strain, u, sigma, vm)
    sworst = 0.0_wp
    do k = 1, msh%nnode
      sworst = max(sworst, maxval(abs(sigma(:, k) - [s, szz])))
    end do
    sworst = sworst/maxval(abs(s))
    call report(sworst <= 1.0e-11_wp, trim(what)//': nodal stresses = the uniform stress, szz too (rel)', &
                sworst, 1.0e-11_wp)
  end subroutine patch

  !> The isotropic law of a material: the Lame parameters of assembly's lame_parameters.
  subroutine isotropic_same()
    type(material_cfg_t) :: m
    type(elastic_law_t) :: law
    type(body_cfg_t) :: b
    type(error_t) :: merr
    real(wp) :: la, mu
    integer :: ip
    m%kind = MAT_ISOTROPIC
    m%young = 2.1e11_wp
    m%poisson = 0.29_wp
    b%young = m%young
    b%poisson = m%poisson
    do ip = 1, 2
      call material_law(m, 30.0_wp, ip == 1, law, merr)
      call lame_parameters(b, ip == 1, la, mu)
      call report(law%isotropic .and. law%lame_lambda == la .and. law%lame_mu == mu .and. &
                  law%d(1, 1) == la + 2*mu .and. law%d(3, 3) == mu, &
                  'isotropic material: the Lame kernel''s parameters, bit for bit, whatever the angle ('// &
                  merge('plane strain)', 'plane stress)', ip == 1))
    end do
  end subroutine isotropic_same

  subroutine turn_swaps()
    type(elastic_law_t) :: l0, l90
    type(error_t) :: merr
    call material_law(ortho(), 0.0_wp, .true., l0, merr)
    call material_law(ortho(), 90.0_wp, .true., l90, merr)
    call report(abs(l90%d(1, 1) - l0%d(2, 2)) <= 1e-12_wp*l0%d(1, 1) .and. &
                abs(l90%d(2, 2) - l0%d(1, 1)) <= 1e-12_wp*l0%d(1, 1) .and. &
                abs(l90%d(4, 1) - l0%d(4, 2)) <= 1e-12_wp*l0%d(1, 1) .and. abs(l90%d(1, 3)) <= 1e-12_wp*l0%d(1, 1), &
                'orthotropic turned by 90 degrees: the axes swap (d11 <-> d22, d41 <-> d42, no coupling)')
  end subroutine turn_swaps

  subroutine eigen_known()
    real(wp) :: q(4, 4), a(4, 4), ev(4), lam(4)
    integer :: k
    ! an orthogonal q (a Householder reflection) and a known spectrum
    q = 0.0_wp
    do k = 1, 4
      q(k, k) = 1.0_wp
    end do
    q = q - 2.0_wp*spread([0.5_wp, 0.5_wp, -0.5_wp, 0.5_wp], 2, 4)*spread([0.5_wp, 0.5_wp, -0.5_wp, 0.5_wp], 1, 4)
    lam = [-3.0_wp, 0.5_wp, 2.0_wp, 7.0_wp]
    a = matmul(q, matmul(reshape([lam(1), 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, lam(2), 0.0_wp, 0.0_wp, &
                                  0.0_wp, 0.0_wp, lam(3), 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, lam(4)], [4, 4]), q))
    call symmetric_eigenvalues(a, ev)
    call report(maxval(abs(ev - lam)) <= 1e-13_wp, 'symmetric_eigenvalues: a known spectrum, ascending', &
                maxval(abs(ev - lam)), 1e-13_wp)
  end subroutine eigen_known

  subroutine bad_materials()
    type(material_cfg_t) :: m
    type(elastic_law_t) :: law
    type(error_t) :: merr
    m = ortho()
    m%nu12 = 4.0_wp          ! nu12^2 = 16 > E1/E2 = 14
    call material_law(m, 0.0_wp, .false., law, merr)
    call report(index(merr%text(), 'not positive definite') > 0 .and. index(merr%text(), 'eigenvalue') > 0, &
                'orthotropic nu12 = 4 with E1/E2 = 14: refused, its compliance''s eigenvalue named')
    m = ortho()
    m%e3 = UNSET
    call material_law(m, 0.0_wp, .true., law, merr)
    call report(index(merr%text(), 'plane strain') > 0 .and. index(merr%text(), 'e3') > 0, &
                'orthotropic without e3 in plane strain: refused, e3 named')
    call material_law(m, 0.0_wp, .false., law, merr)
    call report(.not. merr%failed(), 'orthotropic without e3 in plane stress: accepted (not needed)')
    m = aniso()
    m%c12 = 300.0_wp          ! c12^2 > c11 c22
    call material_law(m, 0.0_wp, .true., law, merr)
    call report(index(merr%text(), 'stiffness is not positive definite') > 0 .and. index(merr%text(), '-') > 0, &
                'anisotropic c12 = 300 > sqrt(c11 c22): refused, the negative eigenvalue named')
  end subroutine bad_materials

end program test_materials
