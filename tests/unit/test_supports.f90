!> Unit tests of a body's supports (module supports) and of the reactions they exert
!! (assembly's support_reactions), on small structured meshes, against values worked out by
!! hand here:
!!  - prescribed_dofs: a clamped, a displaced (with its load stage) and a roller side of a
!!    4 x 2 rectangle, every DOF's mask, value and stage against the rule of the module's
!!    header written out node by node from the coordinates (a corner gets the union of its
!!    sides' constraints, the later side in SIDE_* order wins a component both prescribe);
!!    u_prescribed replaces every prescribed value (stage 1 where it was 0);
!!  - group_conditions: &boundary conditions on named groups, the later overriding the
!!    earlier, another body's skipped, a zero value at stage 0; an unknown group is an
!!    ERR_INPUT error naming the body, where the deck gave it, the group and the groups there are;
!!  - number_free_dofs: the DOFs left free numbered 1..n in increasing order, dof_of its
!!    inverse;
!!  - reactions against the exact solution of uniaxial tension (ux = eps x prescribed on the
!!    right side by a &boundary condition, rollers on the left and bottom): the solved
!!    displacement is the exact linear field, the right side's nodes carry sxx times their
!!    tributary length (h/2 at the corners, h between; sxx = E eps in plane stress (Q1),
!!    E eps / (1 - nu^2) in plane strain (P1)), the left side's the opposite, the rollers
!!    along the bottom none, the free DOFs none; the same on a 2 x 2 x 2 box of hexahedra
!!    (tributary areas A/16, A/8, A/4 of the loaded face);
!!  - a rigid translation prescribed on two sides: the displacement is that translation
!!    everywhere and the reactions vanish (to rounding of K u's terms);
!!  - a clamped rectangle under a uniform top pressure: the reactions balance the load's
!!    resultant and its moment about the origin (statics).
!! The displacements are solved by testing's banded LAPACK solve, not the program's factors.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_supports
  use kinds, only: wp
  use space, only: set_dimension, NDIM, NCOMP, node_dof
  use config, only: body_cfg_t, boundary_cfg_t, traction_cfg_t, BC_FREE, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, SIDE_FRONT, SIDE_BACK, ELEM_Q1, ELEM_P1, MAX_SIDES
  use mesh, only: mesh_t
  use body_system, only: body_system_t
  use supports, only: prescribed_dofs, group_conditions, number_free_dofs
  use assembly, only: assemble_body, expand, support_reactions
  use errors, only: error_t, ERR_INPUT
  use testing, only: report, report_le, test_summary, band_solve, grid_mesh_parts, box_mesh_parts
  implicit none (type, external)

  real(wp), parameter :: E = 2.1e11_wp, nu = 0.25_wp, eps = epsilon(1.0_wp)
  type(traction_cfg_t) :: no_traction(1)

  call set_dimension(2)
  call test_sides()
  call test_groups()
  call test_tension(ELEM_Q1, .false.)
  call test_tension(ELEM_P1, .true.)
  call test_translation()
  call test_statics()
  call set_dimension(3)
  call test_box_tension()
  call test_summary()

contains

  !> A W x H rectangle of nx x ny cells at the origin, E and nu, all sides free.
  function rectangle(w, h, nx, ny, element) result(b)
    real(wp), intent(in) :: w, h
    integer, intent(in) :: nx, ny, element
    type(body_cfg_t) :: b
    b%id = 1
    b%x0 = 0.0_wp
    b%y0 = 0.0_wp
    b%width = w
    b%height = h
    b%nx = nx
    b%ny = ny
    b%element = element
    b%young = E
    b%poisson = nu
    b%bc = BC_FREE
  end function rectangle

  !> Close to within tol (relative to scale).
  elemental logical function near(a, b, scale, tol)
    real(wp), intent(in) :: a, b, scale, tol
    near = abs(a - b) <= tol*scale
  end function near

  ! ---- the side conditions ---------------------------------------------------------------

  subroutine test_sides()
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys, sys2
    logical, allocatable :: pre(:), pre2(:)
    logical :: want_p(2)
    real(wp) :: want_u(2), x, y, up(100)
    integer :: want_s(2), k, c, info, dof
    logical :: ok_p, ok_u, ok_s
    character(len=200) :: msg
    b = rectangle(2.0_wp, 1.0_wp, 4, 2, ELEM_Q1)
    b%bc(SIDE_LEFT) = BC_CLAMPED
    b%bc(SIDE_RIGHT) = BC_DISPLACEMENT
    b%u_side(1:2, SIDE_RIGHT) = [0.01_wp, -0.02_wp]
    b%side_stage(SIDE_RIGHT) = 2
    b%bc(SIDE_BOTTOM) = BC_ROLLER
    call grid_mesh_parts(msh, b, info, msg)
    call prescribed_dofs(msh, b, pre, sys)
    ok_p = sys%ndof == 2*msh%nnode .and. size(pre) == sys%ndof
    ok_u = ok_p
    ok_s = ok_p
    ! the rule, node by node from its coordinates: left (clamped) 0 0 at stage 0; right
    ! (displaced) 0.01 -0.02 at stage 2; bottom (roller: uy) 0 at stage 0, later in SIDE_*
    ! order than left and right, so it wins uy at both bottom corners
    do k = 1, msh%nnode
      x = msh%xy(1, k)
      y = msh%xy(2, k)
      want_p = .false.
      want_u = 0.0_wp
      want_s = 0
      if (x == 0.0_wp) then
        want_p = .true.
        want_u = 0.0_wp
        want_s = 0
      end if
      if (x == 2.0_wp) then
        want_p = .true.
        want_u = [0.01_wp, -0.02_wp]
        want_s = 2
      end if
      if (y == 0.0_wp) then
        want_p(2) = .true.
        want_u(2) = 0.0_wp
        want_s(2) = 0
      end if
      do c = 1, 2
        dof = node_dof(k, c)
        ok_p = ok_p .and. (pre(dof) .eqv. want_p(c))
        ok_u = ok_u .and. sys%u_fixed(dof) == want_u(c)
        ok_s = ok_s .and. sys%dof_stage(dof) == want_s(c)
      end do
    end do
    call report(ok_p, 'prescribed_dofs: clamped left, displaced right, roller bottom (uy): which DOFs')
    call report(ok_u, 'prescribed_dofs: their values; a corner''s shared component the later side''s (bottom''s uy)')
    call report(ok_s, 'prescribed_dofs: their load stages (the displaced side''s 2, a support''s 0)')
    call report(count(pre) == 2*3 + 2*3 + 3, 'prescribed_dofs: 15 DOFs (3 nodes x 2 on each vertical side, 3 '// &
                'bottom nodes between them)')
    ! u_prescribed replaces the values at every prescribed DOF; a support's stage becomes 1
    up = [(0.001_wp*k, k=1, 100)]
    call prescribed_dofs(msh, b, pre2, sys2, u_prescribed=up(1:sys%ndof))
    call report(all(pre2 .eqv. pre) .and. all(merge(sys2%u_fixed == up(1:sys%ndof), sys2%u_fixed == 0.0_wp, pre)) .and. &
                all(merge(sys2%dof_stage == max(sys%dof_stage, 1), sys2%dof_stage == 0, pre)), &
                'prescribed_dofs: u_prescribed replaces every prescribed value, stage 0 becomes 1')
    ! the free DOFs: numbered in increasing order, dof_of the inverse
    call number_free_dofs(pre, sys)
    call report(sys%n == sys%ndof - count(pre) .and. all(sys%dof_of == pack([(k, k=1, sys%ndof)], .not. pre)) .and. &
                all(pack(sys%free_of, pre) == 0) .and. all(sys%free_of(sys%dof_of) == [(k, k=1, sys%n)]), &
                'number_free_dofs: 1..n in increasing DOF order, 0 at prescribed DOFs, dof_of the inverse')
  end subroutine test_sides

  ! ---- the &boundary conditions on groups -------------------------------------------------------

  subroutine test_groups()
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(boundary_cfg_t) :: bd(4)
    logical, allocatable :: pre(:)
    logical :: ok
    real(wp) :: x, y
    integer :: k, info, dx, dy
    character(len=300) :: msg
    type(error_t) :: err
    b = rectangle(2.0_wp, 1.0_wp, 4, 2, ELEM_Q1)
    b%bc(SIDE_RIGHT) = BC_DISPLACEMENT
    b%u_side(1:2, SIDE_RIGHT) = [0.01_wp, -0.02_wp]
    call grid_mesh_parts(msh, b, info, msg)
    call prescribed_dofs(msh, b, pre, sys)
    bd(1)%body = 1
    bd(1)%group = 'top'
    bd(1)%fix(1:2) = [.true., .false.]
    bd(1)%u(1:2) = [0.005_wp, 0.0_wp]
    bd(1)%stage = 3
    bd(2)%body = 2                      ! another body's: skipped
    bd(2)%group = 'left'
    bd(2)%fix(1:2) = .true.
    bd(3)%body = 1                      ! later: overrides the right side's ux, not its uy
    bd(3)%group = 'right'
    bd(3)%fix(1:2) = [.true., .false.]
    bd(3)%u(1:2) = [0.03_wp, 0.0_wp]
    bd(3)%stage = 4
    bd(4)%body = 1                      ! the top's uy at 0: stage 0 (a support)
    bd(4)%group = 'top'
    bd(4)%fix(1:2) = [.false., .true.]
    bd(4)%stage = 5
    call group_conditions(msh, 1, bd, pre, sys, err)
    ok = .not. err%failed()
    do k = 1, msh%nnode
      x = msh%xy(1, k)
      y = msh%xy(2, k)
      dx = node_dof(k, 1)
      dy = node_dof(k, 2)
      if (x == 2.0_wp) then
        ! right: ux 0.03 (stage 4) over the side's 0.01; uy the side's -0.02 unless on top
        ok = ok .and. pre(dx) .and. sys%u_fixed(dx) == 0.03_wp .and. sys%dof_stage(dx) == 4
        if (y == 1.0_wp) then
          ok = ok .and. pre(dy) .and. sys%u_fixed(dy) == 0.0_wp .and. sys%dof_stage(dy) == 0
        else
          ok = ok .and. pre(dy) .and. sys%u_fixed(dy) == -0.02_wp .and. sys%dof_stage(dy) == 1
        end if
      else if (y == 1.0_wp) then
        ! top (not the right corner): ux 0.005 at stage 3, uy 0 at stage 0
        ok = ok .and. pre(dx) .and. sys%u_fixed(dx) == 0.005_wp .and. sys%dof_stage(dx) == 3 .and. &
             pre(dy) .and. sys%u_fixed(dy) == 0.0_wp .and. sys%dof_stage(dy) == 0
      else
        ! the rest free (the left side is body 2's condition)
        ok = ok .and. .not. pre(dx) .and. .not. pre(dy)
      end if
    end do
    call report(ok, 'group_conditions: groups'' components prescribed, the later condition wins, '// &
                'another body''s skipped, a zero value at stage 0')
    ! an unknown group
    bd(1)%group = 'nope'
    bd(1)%origin = 'line 12'
    call group_conditions(msh, 1, bd(1:1), pre, sys, err)
    call report(err%category == ERR_INPUT .and. &
                index(err%text(), 'body 1: line 12: group ''nope'' has no edge on the boundary of this body') == 1 &
                .and. index(err%text(), 'its groups are ''left'', ''right'', ''bottom'', ''top''') > 0, &
                'group_conditions: an unknown group named with the body, the deck line and the groups: '//err%text())
  end subroutine test_groups

  ! ---- reactions ----------------------------------------------------------------------------------

  !> Uniaxial tension of a 2 x 1 rectangle of 4 x 2 cells: rollers on the left (ux) and the
  !! bottom (uy), ux = d on the right side by a &boundary condition, the top free.
  subroutine test_tension(element, plane_strain)
    integer, intent(in) :: element
    logical, intent(in) :: plane_strain
    real(wp), parameter :: w = 2.0_wp, h = 1.0_wp, d = 1.0e-3_wp
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(boundary_cfg_t) :: bd(1)
    type(error_t) :: err
    real(wp), allocatable :: u(:), uf(:), r(:), want(:), exact(:)
    real(wp) :: strain, sxx, ratio, hy, x, y
    integer :: k, info
    character(len=200) :: msg
    character(len=:), allocatable :: tag
    tag = merge(' (Q1, plane stress)', ' (P1, plane strain)', element == ELEM_Q1)
    b = rectangle(w, h, 4, 2, element)
    b%bc(SIDE_LEFT) = BC_ROLLER
    b%bc(SIDE_BOTTOM) = BC_ROLLER
    bd(1)%body = 1
    bd(1)%group = 'right'
    bd(1)%fix(1:2) = [.true., .false.]
    bd(1)%u(1:2) = [d, 0.0_wp]
    call grid_mesh_parts(msh, b, info, msg)
    call assemble_body(msh, b, plane_strain, no_traction, 0, sys, err, boundaries=bd)
    call report(.not. err%failed(), 'tension: assembled'//tag)
    if (err%failed()) return
    allocate (u(sys%n), uf(sys%ndof), r(sys%ndof), want(sys%ndof), exact(sys%ndof))
    call band_solve(sys, u)
    call expand(sys, u, uf)
    ! the exact solution: uniaxial stress sxx, syy = 0
    strain = d/w
    if (plane_strain) then
      sxx = E*strain/(1.0_wp - nu**2)
      ratio = nu/(1.0_wp - nu)
    else
      sxx = E*strain
      ratio = nu
    end if
    hy = h/2.0_wp
    want = 0.0_wp
    do k = 1, msh%nnode
      x = msh%xy(1, k)
      y = msh%xy(2, k)
      exact(node_dof(k, 1)) = strain*x
      exact(node_dof(k, 2)) = -ratio*strain*y
      ! the right side's nodes carry sxx times their tributary length, the left side's the opposite
      if (x == w) want(node_dof(k, 1)) = sxx*merge(hy/2.0_wp, hy, y == 0.0_wp .or. y == h)
      if (x == 0.0_wp) want(node_dof(k, 1)) = -sxx*merge(hy/2.0_wp, hy, y == 0.0_wp .or. y == h)
    end do
    call report_le(maxval(abs(uf - exact))/(strain*w), 1.0e-12_wp, 'tension: the exact linear field'//tag)
    call support_reactions(msh, b, plane_strain, sys, uf, sys%f_applied, r)
    call report_le(maxval(abs(r - want))/(sxx*h), 1.0e-11_wp, 'tension: reactions sxx x tributary length on the '// &
                   'right side, the opposite on the left, none along the bottom roller or at free DOFs'//tag)
    call report(all(pack(r, sys%free_of /= 0) == 0.0_wp), 'tension: exactly 0 at every free DOF'//tag)
    call report_le(abs(sum(r(1::2), mask=[(msh%xy(1, k) == w, k=1, msh%nnode)]) - sxx*h)/(sxx*h), 1.0e-12_wp, &
                   'tension: the right side''s resultant = sxx H'//tag)
  end subroutine test_tension

  !> The same translation prescribed on the left and the right side: u is that translation
  !! everywhere and no support pulls (the reactions are rounding of K u's terms).
  subroutine test_translation()
    real(wp), parameter :: t(2) = [3.0e-4_wp, -2.0e-4_wp]
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(error_t) :: err
    real(wp), allocatable :: u(:), uf(:), r(:), mag(:)
    integer :: info
    character(len=200) :: msg
    b = rectangle(2.0_wp, 1.0_wp, 4, 3, ELEM_Q1)
    b%bc(SIDE_LEFT) = BC_DISPLACEMENT
    b%bc(SIDE_RIGHT) = BC_DISPLACEMENT
    b%u_side(1:2, SIDE_LEFT) = t
    b%u_side(1:2, SIDE_RIGHT) = t
    call grid_mesh_parts(msh, b, info, msg)
    call assemble_body(msh, b, .true., no_traction, 0, sys, err)
    allocate (u(sys%n), uf(sys%ndof), r(sys%ndof), mag(sys%ndof))
    call band_solve(sys, u)
    call expand(sys, u, uf)
    call report_le(max(maxval(abs(uf(1::2) - t(1))), maxval(abs(uf(2::2) - t(2))))/maxval(abs(t)), 1.0e-12_wp, &
                   'translation: the prescribed translation everywhere')
    call support_reactions(msh, b, .true., sys, uf, sys%f_applied, r, mag)
    call report_le(maxval(abs(r))/maxval(mag), 64.0_wp*eps, 'translation: no reaction (relative to K u''s terms)')
  end subroutine test_translation

  !> A rectangle clamped on its left side under a uniform pressure p on its top: the
  !! reactions balance the load, sum r_y = p W, sum r_x = 0, and its moment about the origin,
  !! sum (x r_y - y r_x) = p W^2 / 2.
  subroutine test_statics()
    real(wp), parameter :: w = 3.0_wp, h = 1.0_wp, p = 2.0e6_wp
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    type(error_t) :: err
    real(wp), allocatable :: u(:), uf(:), r(:)
    real(wp) :: fx, fy, mz
    integer :: info, k
    character(len=200) :: msg
    b = rectangle(w, h, 6, 3, ELEM_Q1)
    b%bc(SIDE_LEFT) = BC_CLAMPED
    tr(1)%body = 1
    tr(1)%side = SIDE_TOP
    tr(1)%t0 = [0.0_wp, -p, 0.0_wp]
    call grid_mesh_parts(msh, b, info, msg)
    call assemble_body(msh, b, .true., tr, 1, sys, err)
    allocate (u(sys%n), uf(sys%ndof), r(sys%ndof))
    call band_solve(sys, u)
    call expand(sys, u, uf)
    call support_reactions(msh, b, .true., sys, uf, sys%f_applied, r)
    fx = sum(r(1::2))
    fy = sum(r(2::2))
    mz = sum([(msh%xy(1, k)*r(node_dof(k, 2)) - msh%xy(2, k)*r(node_dof(k, 1)), k=1, msh%nnode)])
    call report_le(max(abs(fx), abs(fy - p*w))/(p*w), 1.0e-12_wp, 'statics: the reactions'' resultant = the '// &
                   'load''s opposite (0, p W)')
    call report_le(abs(mz - p*w**2/2.0_wp)/(p*w**2/2.0_wp), 1.0e-12_wp, 'statics: their moment about the origin = '// &
                   'p W^2 / 2')
    call report(all(pack(r, sys%free_of /= 0) == 0.0_wp) .and. count(r /= 0.0_wp) > 0, &
                'statics: reactions only at the clamped DOFs')
  end subroutine test_statics

  !> A unit box of 2 x 2 x 2 hexahedra: rollers on x = 0, y = 0 and z = 0 (side conditions),
  !! ux = d on x = 1 (a &boundary condition on group 'right'): u = eps (x, -nu y, -nu z)
  !! exactly, and the nodes of the loaded face carry E eps times A/16 (corners), A/8 (edges),
  !! A/4 (centre), the face x = 0 the opposite, the other rollers nothing.
  subroutine test_box_tension()
    real(wp), parameter :: d = 2.0e-4_wp
    type(body_cfg_t) :: b
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(boundary_cfg_t) :: bd(1)
    type(error_t) :: err
    real(wp), allocatable :: u(:), uf(:), r(:), want(:), exact(:)
    real(wp) :: sxx, xyz(3), a
    integer :: k, info, on_edge
    logical, allocatable :: pre(:)
    character(len=200) :: msg
    b%id = 1
    b%x0 = 0.0_wp
    b%y0 = 0.0_wp
    b%z0 = 0.0_wp
    b%width = 1.0_wp
    b%height = 1.0_wp
    b%depth = 1.0_wp
    b%nx = 2
    b%ny = 2
    b%nz = 2
    b%element = ELEM_Q1
    b%young = E
    b%poisson = nu
    b%bc = BC_FREE
    b%bc(SIDE_LEFT) = BC_ROLLER
    b%bc(SIDE_BOTTOM) = BC_ROLLER
    b%bc(SIDE_FRONT) = BC_ROLLER
    bd(1)%body = 1
    bd(1)%group = 'right'
    bd(1)%fix = [.true., .false., .false.]
    bd(1)%u = [d, 0.0_wp, 0.0_wp]
    call box_mesh_parts(msh, b, info, msg)
    ! the side conditions alone: each roller its normal component (front: uz, side_axis 3)
    call prescribed_dofs(msh, b, pre, sys)
    call report(NDIM == 3 .and. count(pre) == 3*9 .and. &
                all([(pre(node_dof(k, 3)) .eqv. (msh%xy(3, k) == 0.0_wp), k=1, msh%nnode)]) .and. &
                all([(pre(node_dof(k, 1)) .eqv. (msh%xy(1, k) == 0.0_wp), k=1, msh%nnode)]), &
                'box: rollers on x = 0, y = 0, z = 0 prescribe ux, uy, uz on their 9 nodes each')
    ! a solid's isotropic law is that of plane_strain = .true. (deck_checks refuses a 3D deck in
    ! plane stress)
    call assemble_body(msh, b, .true., no_traction, 0, sys, err, boundaries=bd)
    call report(.not. err%failed(), 'box: assembled')
    if (err%failed()) return
    allocate (u(sys%n), uf(sys%ndof), r(sys%ndof), want(sys%ndof), exact(sys%ndof))
    call band_solve(sys, u)
    call expand(sys, u, uf)
    sxx = E*d
    a = 1.0_wp
    want = 0.0_wp
    do k = 1, msh%nnode
      xyz = msh%xy(:, k)
      exact(node_dof(k, 1)) = d*xyz(1)
      exact(node_dof(k, 2)) = -nu*d*xyz(2)
      exact(node_dof(k, 3)) = -nu*d*xyz(3)
      ! on the faces x = 0 and x = 1: A/16 at a corner, A/8 on an edge, A/4 at the centre
      on_edge = count(xyz(2:3) == 0.0_wp .or. xyz(2:3) == 1.0_wp)
      if (xyz(1) == 1.0_wp) want(node_dof(k, 1)) = sxx*a/real(4*2**on_edge, wp)
      if (xyz(1) == 0.0_wp) want(node_dof(k, 1)) = -sxx*a/real(4*2**on_edge, wp)
    end do
    call report_le(maxval(abs(uf - exact))/d, 1.0e-12_wp, 'box: the exact linear field eps (x, -nu y, -nu z)')
    call support_reactions(msh, b, .true., sys, uf, sys%f_applied, r)
    call report_le(maxval(abs(r - want))/sxx, 1.0e-11_wp, 'box: reactions E eps x A/16, A/8, A/4 on the loaded face, '// &
                   'the opposite on x = 0, none on the other rollers')
    call report(NCOMP == 3 .and. all(pack(r, sys%free_of /= 0) == 0.0_wp), 'box: exactly 0 at every free DOF')
  end subroutine test_box_tension

end program test_supports
