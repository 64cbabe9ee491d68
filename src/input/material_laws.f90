!> The elastic law of a material for the scene's plane model: the stiffness d relating
!! (sxx, syy, sxy, szz) to (exx, eyy, gxy, ezz) in the x, y axes (config's elastic_law_t),
!! built from a &material's constants (isotropic, orthotropic, anisotropic), its axes
!! turned by an angle about z, and checked positive definite.
!!
!! Voigt order of the plane block: xx, yy, xy (engineering shear gxy = 2 exy), then zz.
!! Plane strain: ezz = 0, szz = d(4, 1:3) e. Plane stress: szz = 0, ezz condensed out (row
!! and column 4 of d are 0). An isotropic law keeps its Lame parameters (the element kernels'
!! fast path) by assembly's formulas, so a body of young and poisson is assembled as before.
!!
!! Orthotropic constants (material axes 1, 2 in the plane, 3 out of it): the compliance of
!! (e11, e22, g12, e33) is
!!   [ 1/E1     -nu12/E1  0      -nu13/E1 ]
!!   [ -nu12/E1  1/E2     0      -nu23/E2 ]
!!   [ 0         0        1/G12   0       ]
!!   [ -nu13/E1 -nu23/E2  0       1/E3    ]
!! (nu_ij/E_i = nu_ji/E_j); the shears g13, g23 do not couple to it, so G13, G23 are not needed
!! in the plane. Plane stress inverts its 3x3 block (E3, nu13, nu23 not needed).
!!
!! Turning the material axes by theta (axis 1 at theta from x): e_material = T e_xy with, for
!! c = cos theta, s = sin theta,
!!   e11 = c^2 exx + s^2 eyy + c s gxy,  e22 = s^2 exx + c^2 eyy - c s gxy,
!!   g12 = -2 c s exx + 2 c s eyy + (c^2 - s^2) gxy,  e33 = ezz,
!! and the energy e_material' D e_material = e_xy' (T' D T) e_xy gives d = T' D T.
module material_laws
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT
  use config, only: material_cfg_t, elastic_law_t, MAT_ISOTROPIC, MAT_ORTHOTROPIC, MAT_ANISOTROPIC, UNSET
  implicit none (type, external)
  private

  public :: isotropic_law, material_law, turned, symmetric_eigenvalues

contains

  !> The isotropic law of young and poisson: plane strain lambda, mu; plane stress the
  !! reduced lambda* = E nu/(1 - nu^2) (assembly's lame_parameters' formulas).
  pure subroutine isotropic_law(young, poisson, plane_strain, law)
    real(wp), intent(in) :: young              !< Young's modulus [stress]
    real(wp), intent(in) :: poisson            !< Poisson's ratio [-]
    logical, intent(in) :: plane_strain        !< plane strain (else plane stress)
    type(elastic_law_t), intent(inout) :: law  !< its stiffness set, region and density kept
    real(wp) :: la, mu
    mu = young/(2.0_wp*(1.0_wp + poisson))
    if (plane_strain) then
      la = young*poisson/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))
    else
      la = young*poisson/(1.0_wp - poisson*poisson)
    end if
    law%isotropic = .true.
    law%lame_lambda = la
    law%lame_mu = mu
    law%d = 0.0_wp
    law%d(1, 1:2) = [la + 2.0_wp*mu, la]
    law%d(2, 1:2) = [la, la + 2.0_wp*mu]
    law%d(3, 3) = mu
    if (plane_strain) then
      law%d(4, 1:2) = la
      law%d(1:2, 4) = la
      law%d(4, 4) = la + 2.0_wp*mu
    end if
  end subroutine isotropic_law

  !> The law of material m, its axis 1 at `angle` degrees from x, in plane strain or plane
  !! stress. On bad input err says why: a constant the model needs and m lacks (named), or a
  !! tensor that is not positive definite (its eigenvalues named).
  subroutine material_law(m, angle, plane_strain, law, err, axisymmetric)
    type(material_cfg_t), intent(in) :: m          !< the material (its kind known)
    real(wp), intent(in) :: angle                  !< axis 1 from x [degrees]
    logical, intent(in) :: plane_strain            !< plane strain (else plane stress)
    !> a body of revolution: the hoop strain is not 0, so the whole 4x4 (c33 too) is needed
    logical, intent(in), optional :: axisymmetric
    type(elastic_law_t), intent(inout) :: law      !< the law (region kept)
    type(error_t), intent(out) :: err              !< ERR_INPUT: what the material lacks, or a law not positive definite
    character(len=:), allocatable :: msg
    real(wp) :: s4(4, 4), c4(4, 4), c3(3, 3), ev(4)
    integer :: n
    logical :: axi

    axi = .false.
    if (present(axisymmetric)) axi = axisymmetric
    law%density = m%density
    select case (m%kind)
    case (MAT_ISOTROPIC)
      call isotropic_law(m%young, m%poisson, plane_strain, law)
      return
    case (MAT_ORTHOTROPIC)
      msg = missing(m, plane_strain, axi)
      if (len(msg) > 0) then
        call err%set(ERR_INPUT, msg)
        return
      end if
      s4 = 0.0_wp
      s4(1, 1) = 1.0_wp/m%e1
      s4(2, 2) = 1.0_wp/m%e2
      s4(1, 2) = -m%nu12/m%e1
      s4(2, 1) = s4(1, 2)
      s4(3, 3) = 1.0_wp/m%g12
      n = 3
      if (plane_strain) then
        n = 4
        s4(4, 4) = 1.0_wp/m%e3
        s4(1, 4) = -m%nu13/m%e1
        s4(4, 1) = s4(1, 4)
        s4(2, 4) = -m%nu23/m%e2
        s4(4, 2) = s4(2, 4)
      end if
      call symmetric_eigenvalues(s4(1:n, 1:n), ev(1:n))
      if (.not. ev(1) > 0.0_wp) then
        msg = 'its compliance is not positive definite: its smallest eigenvalue is '// &
              num(ev(1))//' [1/stress] (eigenvalues '//nums(ev(1:n))//'); the Poisson''s ratios '// &
              'are too large for the moduli (each nu_ij^2 < E_i/E_j, and the determinant > 0)'
        call err%set(ERR_INPUT, msg)
        return
      end if
      c4 = 0.0_wp
      call invert(s4(1:n, 1:n), c4(1:n, 1:n))
    case (MAT_ANISOTROPIC)
      msg = missing(m, plane_strain, axi)
      if (len(msg) > 0) then
        call err%set(ERR_INPUT, msg)
        return
      end if
      c3 = reshape([m%c11, m%c12, value_or_zero(m%c16), m%c12, m%c22, value_or_zero(m%c26), &
                    value_or_zero(m%c16), value_or_zero(m%c26), m%c66], [3, 3])
      c4 = 0.0_wp
      c4(1:3, 1:3) = c3
      if (m%c13 /= UNSET) then
        c4(4, 1:3) = [m%c13, m%c23, value_or_zero(m%c36)]
        c4(1:3, 4) = c4(4, 1:3)
      end if
      n = 3
      if (m%c33 /= UNSET) then
        n = 4
        c4(4, 4) = m%c33
      end if
      call symmetric_eigenvalues(c4(1:n, 1:n), ev(1:n))
      if (.not. ev(1) > 0.0_wp) then
        msg = 'its stiffness is not positive definite: its smallest eigenvalue is '//num(ev(1))// &
              ' [stress] (eigenvalues '//nums(ev(1:n))//')'
        call err%set(ERR_INPUT, msg)
        return
      end if
      if (.not. plane_strain .and. n == 4) then     ! plane stress: szz = 0 condenses ezz out
        c3 = c4(1:3, 1:3) - spread(c4(1:3, 4), 2, 3)*spread(c4(4, 1:3), 1, 3)/c4(4, 4)
        c4 = 0.0_wp
        c4(1:3, 1:3) = c3
      else if (.not. plane_strain) then
        c4(4, :) = 0.0_wp
        c4(:, 4) = 0.0_wp
      end if
    end select
    law%isotropic = .false.
    law%lame_lambda = 0.0_wp
    law%lame_mu = 0.0_wp
    law%d = turned(c4, angle)
  end subroutine material_law

  !> What a kind's model lacks, '' if nothing: orthotropic e1, e2, nu12, g12 always, e3, nu13,
  !! nu23 in plane strain; anisotropic c11 .. c66 always, c13, c23 in plane strain; in plane
  !! stress c13, c23, c33 together or none (none: c11 .. c66 are the plane-stress stiffness).
  function missing(m, plane_strain, axi) result(msg)
    type(material_cfg_t), intent(in) :: m
    logical, intent(in) :: plane_strain
    logical, intent(in) :: axi             ! axisymmetric: c33 too (the hoop strain is not 0)
    character(len=:), allocatable :: msg
    character(len=:), allocatable :: lst
    lst = ''
    if (m%kind == MAT_ORTHOTROPIC) then
      if (m%e1 == UNSET) lst = lst//' e1'
      if (m%e2 == UNSET) lst = lst//' e2'
      if (m%nu12 == UNSET) lst = lst//' nu12'
      if (m%g12 == UNSET) lst = lst//' g12'
      if (len(lst) > 0) then
        msg = 'an orthotropic material needs e1, e2, nu12 and g12; not given:'//lst
        return
      end if
      if (plane_strain) then
        if (m%e3 == UNSET) lst = lst//' e3'
        if (m%nu13 == UNSET) lst = lst//' nu13'
        if (m%nu23 == UNSET) lst = lst//' nu23'
        if (len(lst) > 0) then
          msg = trim(merge('an axisymmetric body needs', 'plane strain needs        ', axi))// &
                ' the out-of-plane constants e3, nu13 and nu23 of an orthotropic '// &
                'material (szz and the plane stiffness depend on them); not given:'//lst
          return
        end if
      end if
    else
      if (m%c11 == UNSET) lst = lst//' c11'
      if (m%c12 == UNSET) lst = lst//' c12'
      if (m%c22 == UNSET) lst = lst//' c22'
      if (m%c66 == UNSET) lst = lst//' c66'
      if (len(lst) > 0) then
        msg = 'an anisotropic material needs c11, c12, c22 and c66 (c16, c26 default to 0); not given:'//lst
        return
      end if
      if (axi) then
        if (m%c13 == UNSET) lst = lst//' c13'
        if (m%c23 == UNSET) lst = lst//' c23'
        if (m%c33 == UNSET) lst = lst//' c33'
        if (len(lst) > 0) then
          msg = 'an axisymmetric body needs the hoop constants c13, c23 and c33 (axis 3 is the hoop '// &
                'direction, its strain ur/r is not 0); not given:'//lst
          return
        end if
      else if (plane_strain) then
        if (m%c13 == UNSET) lst = lst//' c13'
        if (m%c23 == UNSET) lst = lst//' c23'
        if (len(lst) > 0) then
          msg = 'plane strain needs the out-of-plane constants c13 and c23 (szz = c13 exx + c23 eyy + '// &
                'c36 gxy); not given:'//lst
          return
        end if
      else if (m%c13 /= UNSET .or. m%c23 /= UNSET .or. m%c33 /= UNSET .or. m%c36 /= UNSET) then
        if (m%c13 == UNSET) lst = lst//' c13'
        if (m%c23 == UNSET) lst = lst//' c23'
        if (m%c33 == UNSET) lst = lst//' c33'
        if (len(lst) > 0) then
          msg = 'plane stress condenses ezz out with c13, c23 and c33, given together (or none: c11 '// &
                'to c66 are then the plane-stress stiffness); not given:'//lst
          return
        end if
      end if
    end if
    msg = ''
  end function missing

  pure real(wp) function value_or_zero(x)
    real(wp), intent(in) :: x
    value_or_zero = merge(0.0_wp, x, x == UNSET)
  end function value_or_zero

  !> T' c T: the stiffness c of the material axes in the x, y axes, axis 1 at `angle` degrees
  !! from x (module doc).
  pure function turned(c, angle) result(d)
    real(wp), intent(in) :: c(4, 4)     !< (xx, yy, xy, zz) in the material axes [stress]
    real(wp), intent(in) :: angle       !< [degrees]
    real(wp) :: d(4, 4)
    real(wp) :: t(4, 4), co, si, th
    if (angle == 0.0_wp) then
      d = c
      return
    end if
    th = angle*(acos(-1.0_wp)/180.0_wp)
    co = cos(th)
    si = sin(th)
    t = 0.0_wp
    t(1, 1:3) = [co*co, si*si, co*si]
    t(2, 1:3) = [si*si, co*co, -co*si]
    t(3, 1:3) = [-2.0_wp*co*si, 2.0_wp*co*si, co*co - si*si]
    t(4, 4) = 1.0_wp
    d = matmul(transpose(t), matmul(c, t))
    d = 0.5_wp*(d + transpose(d))
  end function turned

  !> The eigenvalues of a small symmetric matrix, ascending (cyclic Jacobi).
  pure subroutine symmetric_eigenvalues(a, ev)
    real(wp), intent(in) :: a(:, :)     !< (n, n), n <= 6
    real(wp), intent(out) :: ev(:)      !< (n)
    real(wp) :: b(size(a, 1), size(a, 1)), th, t, c, s, off, tau, bpp, bqq, bpq, row(size(a, 1))
    integer :: n, p, q, sweep, k
    n = size(a, 1)
    b = a
    do sweep = 1, 60
      off = 0.0_wp
      do p = 1, n - 1
        off = off + sum(b(p, p + 1:n)**2)
      end do
      if (off <= (epsilon(1.0_wp)*maxval(abs(b)))**2) exit
      do p = 1, n - 1
        do q = p + 1, n
          if (b(p, q) == 0.0_wp) cycle
          th = (b(q, q) - b(p, p))/(2.0_wp*b(p, q))
          t = sign(1.0_wp, th)/(abs(th) + sqrt(th*th + 1.0_wp))
          c = 1.0_wp/sqrt(t*t + 1.0_wp)
          s = t*c
          tau = s/(1.0_wp + c)
          bpp = b(p, p)
          bqq = b(q, q)
          bpq = b(p, q)
          row = b(p, :)
          do k = 1, n
            if (k == p .or. k == q) cycle
            b(p, k) = row(k) - s*(b(q, k) + tau*row(k))
            b(q, k) = b(q, k) + s*(row(k) - tau*b(q, k))
            b(k, p) = b(p, k)
            b(k, q) = b(q, k)
          end do
          b(p, p) = bpp - t*bpq
          b(q, q) = bqq + t*bpq
          b(p, q) = 0.0_wp
          b(q, p) = 0.0_wp
        end do
      end do
    end do
    do k = 1, n
      ev(k) = b(k, k)
    end do
    do p = 2, n          ! insertion sort
      t = ev(p)
      q = p - 1
      do while (q >= 1)
        if (ev(q) <= t) exit
        ev(q + 1) = ev(q)
        q = q - 1
      end do
      ev(q + 1) = t
    end do
  end subroutine symmetric_eigenvalues

  !> c = s^-1 of a small symmetric positive definite matrix (Gauss-Jordan; s is well
  !! conditioned enough once its eigenvalues are checked positive).
  pure subroutine invert(s, c)
    real(wp), intent(in) :: s(:, :)
    real(wp), intent(out) :: c(:, :)
    real(wp) :: a(size(s, 1), 2*size(s, 1)), piv
    integer :: n, i, k
    n = size(s, 1)
    a = 0.0_wp
    a(:, 1:n) = s
    do i = 1, n
      a(i, n + i) = 1.0_wp
    end do
    do i = 1, n
      piv = a(i, i)
      a(i, :) = a(i, :)/piv
      do k = 1, n
        if (k /= i) a(k, :) = a(k, :) - a(k, i)*a(i, :)
      end do
    end do
    c = a(:, n + 1:2*n)
    c = 0.5_wp*(c + transpose(c))
  end subroutine invert

  function num(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=32) :: buf
    write (buf, '(es11.4)') x
    s = trim(adjustl(buf))
  end function num

  function nums(x) result(s)
    real(wp), intent(in) :: x(:)
    character(len=:), allocatable :: s
    integer :: k
    s = ''
    do k = 1, size(x)
      s = s//merge(', ', '  ', k > 1)//num(x(k))
    end do
    s = trim(adjustl(s))
  end function nums

end module material_laws
