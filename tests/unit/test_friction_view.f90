!> Unit tests of what the output shows of a frictional solution (module friction_view) and of
!! the friction rows' helpers of module contact_interface, on a synthetic interface built here:
!! one pair, four slave nodes in space, each with its normal row, node 4 on a plane of
!! symmetry with one tangential row (its tangent-2 row dropped), Coulomb mu = 0.5, forces
!! chosen by hand:
!!  - disc_rows pairs the tangent-1 and tangent-2 rows of nodes 1-3 and leaves node 4 out;
!!    disc_positions finds them among a permuted subset of rows;
!!  - row_bounds gives each tangential row the radius mu lam_n of its node (Tresca: g D);
!!  - split_friction: the normal rows alone as the view (lengths, pair ranges, B rows), the
!!    tangential force as its two frame components and as a vector (against the frame's
!!    tangents written out here for n = (0, 1, 0), and in the tangent plane elsewhere), the shear = force / tributary area, the slip and its
!!    increment from the rows' w and gap, the bound, and the states: a node whose force's
!!    length is its disc's radius slips (whichever direction it points in: a box would call
!!    a force at 45 degrees inside), one inside sticks, one without normal force is open;
!!    the node with one tangential row has 0 across the plane;
!!  - in the plane (NDIM = 2) the same view keeps one component, the old layout.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_friction_view
  use kinds, only: wp
  use space, only: set_dimension, frame_of
  use config, only: FRICTION_COULOMB, FRICTION_TRESCA
  use contact_interface, only: interface_t, disc_rows, disc_positions, row_bounds, DIR_NORMAL
  use contact_types, only: contact_result_t
  use friction_view, only: tangential_t, split_friction, NODE_STICK, NODE_SLIP, NODE_OPEN
  use testing, only: report, report_le, test_summary
  implicit none (type, external)

  real(wp), parameter :: mu = 0.5_wp, eps = epsilon(1.0_wp)

  call set_dimension(3)
  call test_space()
  call set_dimension(2)
  call test_plane()
  call test_summary()

contains

  !> Four nodes in space: rows 1-4 normal, 5-8 tangent 1 of nodes 1-4, 9-11 tangent 2 of
  !! nodes 1-3 (node 4's dropped).
  subroutine space_interface(itf)
    type(interface_t), intent(out) :: itf
    real(wp) :: n(3, 4)
    integer :: k, k0
    n(:, 1) = [0.0_wp, 1.0_wp, 0.0_wp]
    n(:, 2) = [0.6_wp, 0.8_wp, 0.0_wp]
    n(:, 3) = [0.0_wp, 0.6_wp, 0.8_wp]
    n(:, 4) = [0.0_wp, 1.0_wp, 0.0_wp]
    itf%m = 11
    itf%npair = 1
    itf%pair_ptr = [1, 12]
    itf%pair_body = reshape([1, 2], [2, 1])
    itf%pair_slave = [1]
    itf%pair_friction = [FRICTION_COULOMB]
    itf%pair_mu = [mu]
    itf%pair_slip = [0.0_wp]
    itf%dir = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2]
    itf%nrow = [1, 2, 3, 4, 1, 2, 3, 4, 1, 2, 3]
    allocate (itf%pair_of(11), itf%s(11), itf%xy(3, 11), itf%frame(3, 3, 11), itf%g0(11), itf%trib(11), &
              itf%node(11, 2))
    itf%pair_of = 1
    itf%s = 0.0_wp
    itf%xy = 0.0_wp
    itf%g0 = 0.0_wp
    itf%node = 0
    do k = 1, 11
      itf%frame(:, :, k) = frame_of(n(:, itf%nrow(k)))
      itf%trib(k) = 0.5_wp*itf%nrow(k)
    end do
    do k = 1, 2
      allocate (itf%b(k)%ptr(12), itf%b(k)%dof(11), itf%b(k)%val(11))
      itf%b(k)%ptr = [(k0, k0=1, 12)]
      itf%b(k)%dof = [(k0, k0=1, 11)]
      itf%b(k)%val = 1.0_wp
    end do
  end subroutine space_interface

  subroutine test_space()
    type(interface_t) :: itf, itf_n
    type(contact_result_t) :: res, res_n
    type(tangential_t) :: tg
    integer, allocatable :: pr(:, :), pp(:, :)
    real(wp) :: lb(11), ub(11), v(3), r
    integer :: k
    call space_interface(itf)
    pr = disc_rows(itf)
    call report(size(pr, 2) == 3 .and. all(pr(:, 1) == [5, 9]) .and. all(pr(:, 2) == [6, 10]) .and. &
                all(pr(:, 3) == [7, 11]), 'disc_rows: the tangent-1 and tangent-2 rows of nodes 1-3, not node 4')
    pp = disc_positions(itf, [11, 3, 7, 8, 9, 5])
    call report(size(pp, 2) == 2 .and. all(pp(:, 1) == [6, 5]) .and. all(pp(:, 2) == [3, 1]), &
                'disc_positions: the discs among a permuted subset (positions in it)')
    ! forces: node 1 on its circle at 45 degrees, node 2 inside, node 3 open (no normal force,
    ! no tangential force), node 4 on its interval's end
    allocate (res%lam(11), res%lam_body(11, 2), res%w(11, 2), res%gap(11), res%obstacle(11, 2))
    res%lam = 0.0_wp
    res%lam(1:4) = [2.0_wp, 4.0_wp, 0.0_wp, 1.0_wp]
    r = mu*2.0_wp/sqrt(2.0_wp)
    res%lam([5, 9]) = [r, r]
    res%lam([6, 10]) = [0.3_wp, -0.4_wp]
    res%lam(8) = -0.5_wp
    res%lam_body(:, 1) = res%lam
    res%lam_body(:, 2) = res%lam
    do k = 1, 11
      res%w(k, :) = [0.01_wp*k, 0.002_wp*k]
      res%gap(k) = 0.001_wp*k
    end do
    res%obstacle = 0.0_wp
    res%residual = 0.0_wp
    call row_bounds(itf, res%lam, lb, ub)
    call report(all(ub(5:8) == mu*res%lam(1:4)) .and. all(ub(9:11) == mu*res%lam(1:3)) .and. all(lb(5:11) == -ub(5:11)) &
                .and. all(lb(1:4) == 0.0_wp), 'row_bounds: each tangential row the radius mu lam_n of its node')
    call split_friction(itf, res, itf_n, res_n, tg)
    call report(itf_n%m == 4 .and. all(itf_n%pair_ptr == [1, 5]) .and. size(res_n%lam) == 4 .and. &
                all(res_n%lam == res%lam(1:4)) .and. all(itf_n%dir == DIR_NORMAL) .and. itf_n%b(1)%ptr(5) == 5, &
                'split_friction: the view is the normal rows alone')
    call report(tg%on .and. all(shape(tg%force) == [2, 4]) .and. all(tg%force(:, 1) == [r, r]) .and. &
                all(tg%force(:, 2) == [0.3_wp, -0.4_wp]) .and. all(tg%force(:, 3) == 0.0_wp) .and. &
                all(tg%force(:, 4) == [-0.5_wp, 0.0_wp]), 'split_friction: the force along the two tangents (none across the plane)')
    ! the vector: for n = (0, 1, 0) the frame's tangents are t1 = n x e_x = (0, 0, -1) and
    ! t2 = n x t1 = (-1, 0, 0) (module space, frame_of)
    v = tg%force_xyz(:, 1) - [-r, 0.0_wp, -r]
    call report_le(norm2(v), 4.0_wp*eps, 'split_friction: the force as a vector (node 1: r t1 + r t2 = (-r, 0, -r))')
    v = tg%force_xyz(:, 4) - [0.0_wp, 0.0_wp, 0.5_wp]
    call report_le(norm2(v), 4.0_wp*eps, 'split_friction: the force as a vector (node 4: -0.5 t1 = (0, 0, 0.5))')
    v = tg%force_xyz(:, 2) - (0.3_wp*itf%frame(:, 2, 2) - 0.4_wp*itf%frame(:, 3, 2))
    call report_le(norm2(v) + abs(dot_product(tg%force_xyz(:, 2), [0.6_wp, 0.8_wp, 0.0_wp])), 4.0_wp*eps, &
                   'split_friction: the force as a vector (node 2: 0.3 t1 - 0.4 t2, across its normal)')
    call report_le(maxval(abs(tg%shear(:, 2) - tg%force(:, 2)/1.0_wp)), eps, 'split_friction: shear = force / tributary area')
    call report(all(tg%slip(:, 2) == [res%w(6, 1) + res%w(6, 2), res%w(10, 1) + res%w(10, 2)]) .and. &
                all(tg%slip_increment(:, 2) == [res%gap(6), res%gap(10)]), 'split_friction: the slip and its increment')
    call report(all(tg%bound == mu*res%lam(1:4)), 'split_friction: the bound mu lam_n')
    call report(tg%state(1) == NODE_SLIP .and. tg%state(2) == NODE_STICK .and. tg%state(3) == NODE_OPEN .and. &
                tg%state(4) == NODE_SLIP, 'split_friction: on the circle at 45 degrees slips, inside sticks, '// &
                'no normal force open, the interval''s end slips')
    ! Tresca: the radius g D of the node's tributary area
    itf%pair_friction = [FRICTION_TRESCA]
    itf%pair_slip = [3.0_wp]
    call row_bounds(itf, res%lam, lb, ub)
    call report(all(ub(5:8) == 3.0_wp*itf%trib(5:8)) .and. all(ub(9:11) == 3.0_wp*itf%trib(9:11)), &
                'row_bounds: Tresca, the radius g D')
  end subroutine test_space

  !> The plane: two nodes, one tangential row each; the view keeps one component.
  subroutine test_plane()
    type(interface_t) :: itf, itf_n
    type(contact_result_t) :: res, res_n
    type(tangential_t) :: tg
    integer :: k
    itf%m = 4
    itf%npair = 1
    itf%pair_ptr = [1, 5]
    itf%pair_body = reshape([1, 2], [2, 1])
    itf%pair_slave = [1]
    itf%pair_friction = [FRICTION_COULOMB]
    itf%pair_mu = [mu]
    itf%pair_slip = [0.0_wp]
    itf%dir = [0, 0, 1, 1]
    itf%nrow = [1, 2, 1, 2]
    allocate (itf%pair_of(4), itf%s(4), itf%xy(2, 4), itf%frame(2, 2, 4), itf%g0(4), itf%trib(4), itf%node(4, 2))
    itf%pair_of = 1
    itf%s = 0.0_wp
    itf%xy = 0.0_wp
    itf%g0 = 0.0_wp
    itf%trib = 1.0_wp
    itf%node = 0
    do k = 1, 4
      itf%frame(:, :, k) = frame_of([0.0_wp, 1.0_wp])
    end do
    do k = 1, 2
      allocate (itf%b(k)%ptr(5), itf%b(k)%dof(4), itf%b(k)%val(4))
      itf%b(k)%ptr = [1, 2, 3, 4, 5]
      itf%b(k)%dof = [1, 2, 3, 4]
      itf%b(k)%val = 1.0_wp
    end do
    allocate (res%lam(4), res%lam_body(4, 2), res%w(4, 2), res%gap(4), res%obstacle(4, 2))
    res%lam = [2.0_wp, 2.0_wp, 1.0_wp, -0.2_wp]
    res%lam_body(:, 1) = res%lam
    res%lam_body(:, 2) = res%lam
    res%w = 0.0_wp
    res%gap = 0.0_wp
    res%obstacle = 0.0_wp
    res%residual = 0.0_wp
    call report(size(disc_rows(itf), 2) == 0, 'disc_rows: none in the plane')
    call split_friction(itf, res, itf_n, res_n, tg)
    call report(all(shape(tg%force) == [1, 2]) .and. all(tg%force(1, :) == [1.0_wp, -0.2_wp]) .and. &
                tg%state(1) == NODE_SLIP .and. tg%state(2) == NODE_STICK, &
                'split_friction in the plane: one component, the interval''s end slips')
  end subroutine test_plane

end program test_friction_view
