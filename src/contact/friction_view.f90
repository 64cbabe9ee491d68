!> What the output shows of a frictional solution: the interface and the result on the
!! normal rows alone (every dataset and line of a frictionless result keeps its meaning and
!! its length, one entry per contact node), and beside it, per normal row, the tangential
!! force of its node, the shear traction, the slip and the node's state (stick, slip, open).
!! In space a node's tangential force, shear and slip have two components (along the frame's
!! tangents t1, t2), the force also as a vector, and its state compares the force's length
!! with the radius of its disc.
module friction_view
  use kinds, only: wp
  use space, only: NCOMP, NDIM
  use contact_interface, only: interface_t, row_bounds, contact_resultant, DIR_NORMAL
  use contact_types, only: contact_result_t
  implicit none (type, external)
  private

  integer, parameter, public :: NODE_OPEN = 0    !< no normal force
  integer, parameter, public :: NODE_STICK = 1   !< in contact, the tangential force inside its bound
  integer, parameter, public :: NODE_SLIP = 2    !< in contact (Tresca: or not), the tangential force at its bound
  integer, parameter, public :: NODE_NONE = -1   !< a node of a frictionless pair
  character(len=5), parameter, public :: node_state_names(-1:2) = ['none ', 'open ', 'stick', 'slip ']

  !> A relative margin below the bound that still counts as at the bound (slip), at least:
  !! a projected bound is exact, but the Robin iterate's two sides agree only to its
  !! residual, so the margin is the larger of this and 100 x the residual.
  real(wp), parameter :: AT_BOUND = 1.0e-9_wp

  !> The tangential part of a solution, one entry per normal row of the view.
  type, public :: tangential_t
    logical :: on = .false.                   !< some pair has friction
    !> the resultant of all contact forces (normal and tangential) on side 1 of each pair,
    !! and of all pairs together [force]
    real(wp), allocatable :: resultant(:, :)  !< (NCOMP, npair)
    real(wp), allocatable :: resultant_all(:) !< (NCOMP)
    !> (NDIM - 1, nodes) tangential force of the node along each tangent (0: frictionless pair) [force]
    real(wp), allocatable :: force(:, :)
    real(wp), allocatable :: force_xyz(:, :)  !< (NDIM, nodes) the tangential force as a vector [force]
    real(wp), allocatable :: shear(:, :)      !< (NDIM - 1, nodes) force / tributary length [stress]
    real(wp), allocatable :: bound(:)         !< the bound of |force| (Tresca's, or mu x the normal force) [force]
    !> (NDIM - 1, nodes) relative tangential displacement along each tangent [length]
    real(wp), allocatable :: slip(:, :)
    real(wp), allocatable :: slip_increment(:, :) !< (NDIM - 1, nodes) slip less the slip the step started from [length]
    integer, allocatable :: state(:)          !< NODE_*
  end type tangential_t

  public :: split_friction

contains

  !> The normal rows of itf and res as an interface and a result of their own (itf_n, res_n;
  !! pair ranges renumbered, the B rows and every row vector restricted), and the
  !! tangential part of each normal row's node in tg. Without friction the copies are
  !! exact copies and tg%on is false.
  subroutine split_friction(itf, res, itf_n, res_n, tg)
    type(interface_t), intent(in) :: itf
    type(contact_result_t), intent(in) :: res
    type(interface_t), intent(out) :: itf_n
    type(contact_result_t), intent(out) :: res_n
    type(tangential_t), intent(out) :: tg
    integer, allocatable :: keep(:), tan(:, :)
    real(wp), allocatable :: lb(:), ub(:)
    integer :: k, p, s, n, e, q, mn, j
    real(wp) :: margin
    keep = pack([(k, k=1, itf%m)], itf%dir == DIR_NORMAL)
    mn = size(keep)
    itf_n%m = mn
    itf_n%npair = itf%npair
    itf_n%mortar = itf%mortar
    itf_n%pair_body = itf%pair_body
    itf_n%pair_slave = itf%pair_slave
    itf_n%pair_friction = itf%pair_friction
    itf_n%pair_mu = itf%pair_mu
    itf_n%pair_slip = itf%pair_slip
    allocate (itf_n%pair_ptr(itf%npair + 1))
    itf_n%pair_ptr(1) = 1
    do p = 1, itf%npair
      itf_n%pair_ptr(p + 1) = itf_n%pair_ptr(p) + count(itf%dir(itf%pair_ptr(p):itf%pair_ptr(p + 1) - 1) == DIR_NORMAL)
    end do
    itf_n%pair_of = itf%pair_of(keep)
    itf_n%s = itf%s(keep)
    itf_n%xy = itf%xy(:, keep)
    itf_n%frame = itf%frame(:, :, keep)
    itf_n%g0 = itf%g0(keep)
    itf_n%trib = itf%trib(keep)
    itf_n%node = itf%node(keep, :)
    itf_n%dir = itf%dir(keep)
    itf_n%nrow = [(k, k=1, mn)]
    do s = 1, 2
      n = 0
      do k = 1, mn
        n = n + itf%b(s)%ptr(keep(k) + 1) - itf%b(s)%ptr(keep(k))
      end do
      allocate (itf_n%b(s)%ptr(mn + 1), itf_n%b(s)%dof(n), itf_n%b(s)%val(n))
      itf_n%b(s)%ptr(1) = 1
      q = 0
      do k = 1, mn
        do e = itf%b(s)%ptr(keep(k)), itf%b(s)%ptr(keep(k) + 1) - 1
          q = q + 1
          itf_n%b(s)%dof(q) = itf%b(s)%dof(e)
          itf_n%b(s)%val(q) = itf%b(s)%val(e)
        end do
        itf_n%b(s)%ptr(k + 1) = q + 1
      end do
    end do

    res_n = res
    if (allocated(res%lam)) then
      res_n%lam = res%lam(keep)
      res_n%lam_body = res%lam_body(keep, :)
      res_n%w = res%w(keep, :)
      res_n%gap = res%gap(keep)
      res_n%obstacle = res%obstacle(keep, :)
    end if

    allocate (tg%resultant(NCOMP, itf%npair), tg%resultant_all(NCOMP))
    tg%resultant = 0.0_wp
    tg%resultant_all = 0.0_wp
    if (allocated(res%lam)) then
      tg%resultant_all = contact_resultant(itf, 1, res%lam, 1, itf%m)
      do p = 1, itf%npair
        tg%resultant(:, p) = contact_resultant(itf, 1, res%lam, itf%pair_ptr(p), itf%pair_ptr(p + 1) - 1)
      end do
    end if
    tg%on = any(itf%dir > DIR_NORMAL)
    if (.not. tg%on) return
    ! the tangential rows of each normal row (0: none)
    allocate (tan(NDIM - 1, itf%m))
    tan = 0
    do k = 1, itf%m
      if (itf%dir(k) > DIR_NORMAL) tan(itf%dir(k), itf%nrow(k)) = k
    end do
    allocate (tg%force(NDIM - 1, mn), tg%force_xyz(NDIM, mn), tg%shear(NDIM - 1, mn), tg%bound(mn), &
              tg%slip(NDIM - 1, mn), tg%slip_increment(NDIM - 1, mn), tg%state(mn))
    tg%force = 0.0_wp
    tg%force_xyz = 0.0_wp
    tg%shear = 0.0_wp
    tg%bound = 0.0_wp
    tg%slip = 0.0_wp
    tg%slip_increment = 0.0_wp
    tg%state = NODE_NONE
    if (.not. allocated(res%lam)) return
    allocate (lb(itf%m), ub(itf%m))
    call row_bounds(itf, res%lam, lb, ub)
    margin = max(AT_BOUND, 100.0_wp*res%residual)
    do k = 1, mn
      if (all(tan(:, keep(k)) == 0)) cycle
      do j = 1, NDIM - 1
        q = tan(j, keep(k))
        if (q == 0) cycle      ! a node on a plane of symmetry: no force across it
        tg%force(j, k) = res%lam(q)
        if (itf%trib(q) > 0.0_wp) tg%shear(j, k) = res%lam(q)/itf%trib(q)
        tg%slip(j, k) = res%w(q, 1) + res%w(q, 2)
        tg%slip_increment(j, k) = res%gap(q)
        tg%force_xyz(:, k) = tg%force_xyz(:, k) + res%lam(q)*itf%frame(:, j + 1, q)
      end do
      q = maxval(tan(:, keep(k)))
      tg%bound(k) = ub(q)
      if (norm2(tg%force(:, k)) >= (1.0_wp - margin)*ub(q) .and. ub(q) > 0.0_wp) then
        tg%state(k) = NODE_SLIP
      else if (res%lam(keep(k)) > 0.0_wp) then
        tg%state(k) = NODE_STICK
      else
        tg%state(k) = NODE_OPEN
      end if
    end do
  end subroutine split_friction

end module friction_view
