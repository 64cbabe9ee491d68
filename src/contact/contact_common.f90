!> Small pieces every contact solver shares: the residual of an iterate on the contact
!! rows, a body's own vector out of the side layout and back (gather, scatter),
!! finiteness tests and the thread count over the bodies.
module contact_common
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use contact_interface, only: interface_t, slot_row, slot_side, has_friction, row_bounds, disc_rows, DIR_NORMAL
  use condense, only: body_condensed_t
  use contact_types, only: contact_result_t
  implicit none (type, external)
  private

  public :: interface_residual, gather, scatter, partner_slots, pair_positions, maxabs, all_finite, body_threads

contains

  !> A body's own vector x(slots) of a side-layout array x (m, 2) (body_condensed_t%slots).
  pure function gather(x, slots) result(y)
    real(wp), intent(in) :: x(:, :)         !< (m, 2) side layout
    integer, intent(in) :: slots(:)         !< the body's positions, row + (side - 1) m
    real(wp) :: y(size(slots))
    integer :: k, m
    m = size(x, 1)
    do k = 1, size(slots)
      y(k) = x(slot_row(slots(k), m), slot_side(slots(k), m))
    end do
  end function gather

  !> x(slots) = y: a body's own vector into the side-layout array x (m, 2).
  pure subroutine scatter(y, slots, x)
    real(wp), intent(in) :: y(:)            !< the body's vector
    integer, intent(in) :: slots(:)         !< the body's positions, row + (side - 1) m
    real(wp), intent(inout) :: x(:, :)      !< (m, 2) side layout
    integer :: k, m
    m = size(x, 1)
    do k = 1, size(slots)
      x(slot_row(slots(k), m), slot_side(slots(k), m)) = y(k)
    end do
  end subroutine scatter

  !> The slots of the other side of the same rows: (row, s) -> (row, 3 - s).
  pure function partner_slots(slots, m) result(q)
    integer, intent(in) :: slots(:)         !< a body's positions, row + (side - 1) m
    integer, intent(in) :: m                !< contact rows of all pairs
    integer :: q(size(slots))
    integer :: k
    do k = 1, size(slots)
      if (slots(k) > m) then
        q(k) = slots(k) - m
      else
        q(k) = slots(k) + m
      end if
    end do
  end function partner_slots

  !> The positions in cbody's own vectors of the rows of pair p (contiguous: a body's rows
  !! go pair by pair), as first and last (last < first: the body is not in the pair).
  pure function pair_positions(cbody, contact_line, p) result(r)
    type(body_condensed_t), intent(in) :: cbody
    type(interface_t), intent(in) :: contact_line
    integer, intent(in) :: p                !< pair
    integer :: r(2)
    integer :: k, row
    r = [1, 0]
    do k = 1, cbody%m
      row = slot_row(cbody%slots(k), contact_line%m)
      if (contact_line%pair_of(row) /= p) cycle
      if (r(2) < r(1)) r(1) = k
      r(2) = k
    end do
  end function pair_positions

  !> Gap, imbalance, penetration, complementarity and equilibrium of res%lam_body, res%w.
  subroutine interface_residual(contact_line, bodies, res)
    type(interface_t), intent(in) :: contact_line         !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)       !< condensed bodies (scales)
    type(contact_result_t), intent(inout) :: res          !< lam_body, w in; residuals out
    real(wp) :: uscale, lnorm, lmax
    integer :: i
    if (contact_line%m == 0) then
      res%residual = 0.0_wp
      return
    end if
    res%lam = 0.5_wp*(res%lam_body(:, 1) + res%lam_body(:, 2))
    res%gap = res%w(:, 1) + res%w(:, 2) - contact_line%g0
    uscale = max(maxabs(contact_line%g0), maxabs(res%w(:, 1)), maxabs(res%w(:, 2)), tiny(1.0_wp))
    do i = 1, size(bodies)
      uscale = max(uscale, maxabs(bodies(i)%b))
    end do
    lnorm = norm2(res%lam)
    if (lnorm > 0.0_wp) then
      res%imbalance = norm2(res%lam_body(:, 1) - res%lam_body(:, 2))/lnorm
    else
      res%imbalance = 0.0_wp
    end if
    if (has_friction(contact_line)) then
      call frictional_residual(contact_line, uscale, res)
    else
      lmax = maxval(res%lam)
      res%penetration = max(maxval(res%gap), 0.0_wp)/uscale
      res%complementarity = 0.0_wp
      if (lmax > 0.0_wp) then
        do i = 1, contact_line%m
          res%complementarity = max(res%complementarity, max(res%lam(i), 0.0_wp)*abs(res%gap(i)))
        end do
        res%complementarity = res%complementarity/(lmax*uscale)
      end if
    end if
    ! a floating body's equilibrium (its load against its own contact force): an inner
    ! solve that stopped on inner_max_it may leave it unmet, and then no run converges
    res%equilibrium = 0.0_wp
    do i = 1, size(bodies)
      if (bodies(i)%nrig == 0) cycle
      associate (lam_i => gather(res%lam_body, bodies(i)%slots))
        res%equilibrium = max(res%equilibrium, norm2(matmul(bodies(i)%rg, lam_i) - bodies(i)%re)/ &
                              max(norm2(bodies(i)%re), merge(norm2(bodies(i)%rg)*norm2(lam_i), 0.0_wp, &
                                  all(bodies(i)%re == 0.0_wp)), tiny(1.0_wp)))
      end associate
    end do
    res%residual = max(res%imbalance, res%penetration, res%complementarity, res%equilibrium)
    res%active = count(res%lam > 0.0_wp .and. contact_line%dir == DIR_NORMAL)
  end subroutine interface_residual

  !> Penetration and complementarity with tangential rows: the normal rows as without
  !! friction; on a tangential row with bound t (row_bounds at the mean normal force) the
  !! force outside [-t, t], a slip where the node sticks (min(t - |lam_t|, lam_max) |slip|:
  !! a bound far above every force weighs a stuck node's slip as lam_max, not as the bound,
  !! which would weigh its rounding) and a slip against the force (max(-lam_t slip, 0)) all
  !! count, scaled like the normal ones (the largest normal force lam_max and the
  !! displacement scale). In space a node's two tangential rows count as one disc: its
  !! force's length against the radius, and the slip's part across the force
  !! (|lam_t| |slip - (slip.nu) nu|, nu = lam_t / |lam_t|: slip and force must be parallel).
  subroutine frictional_residual(contact_line, uscale, res)
    type(interface_t), intent(in) :: contact_line
    real(wp), intent(in) :: uscale
    type(contact_result_t), intent(inout) :: res
    real(wp), allocatable :: lb(:), ub(:)
    integer, allocatable :: pr(:, :)
    logical, allocatable :: in_disc(:)
    real(wp) :: lmax, pen, comp, lt(2), sl(2), ln
    integer :: i
    allocate (lb(contact_line%m), ub(contact_line%m), in_disc(contact_line%m))
    call row_bounds(contact_line, res%lam, lb, ub)
    lmax = maxval(res%lam, mask=contact_line%dir == DIR_NORMAL)
    pen = 0.0_wp
    comp = 0.0_wp
    pr = disc_rows(contact_line)
    in_disc = .false.
    do i = 1, size(pr, 2)
      in_disc(pr(:, i)) = .true.
      lt = res%lam(pr(:, i))
      sl = res%gap(pr(:, i))
      ln = norm2(lt)
      comp = max(comp, min(max(ub(pr(1, i)) - ln, 0.0_wp), lmax)*norm2(sl), max(-dot_product(lt, sl), 0.0_wp), &
                 max(ln - ub(pr(1, i)), 0.0_wp)*uscale)
      if (ln > 0.0_wp) comp = max(comp, ln*norm2(sl - dot_product(sl, lt/ln)*lt/ln))
    end do
    do i = 1, contact_line%m
      if (in_disc(i)) cycle
      if (contact_line%dir(i) == DIR_NORMAL) then
        pen = max(pen, res%gap(i))
        comp = max(comp, max(res%lam(i), 0.0_wp)*abs(res%gap(i)))
      else
        comp = max(comp, min(max(ub(i) - abs(res%lam(i)), 0.0_wp), lmax)*abs(res%gap(i)), &
                   max(-res%lam(i)*res%gap(i), 0.0_wp), &
                   max(abs(res%lam(i)) - ub(i), 0.0_wp)*uscale)
      end if
    end do
    res%penetration = max(pen, 0.0_wp)/uscale
    res%complementarity = 0.0_wp
    if (lmax > 0.0_wp) res%complementarity = comp/(lmax*uscale)
  end subroutine frictional_residual

  !> max |x_i| (0 for an empty x).
  real(wp) function maxabs(x)
    real(wp), intent(in) :: x(:)   !< a vector
    maxabs = 0.0_wp
    if (size(x) > 0) maxabs = maxval(abs(x))
  end function maxabs

  !> True when every entry of x (rank 1 or 2) is finite.
  logical function all_finite(x)
    real(wp), intent(in) :: x(..)   !< a vector or a matrix
    select rank (x)
    rank (1)
      all_finite = all(ieee_is_finite(x))
    rank (2)
      all_finite = all(ieee_is_finite(x))
    rank default
      all_finite = .false.
    end select
  end function all_finite

  !> Threads over the bodies and the interface-sized loops: the run's threads (OMP max threads,
  !! which the driver sets to the user's OMP_NUM_THREADS).
  integer function body_threads()
    use omp_lib, only: omp_get_max_threads
    body_threads = max(1, omp_get_max_threads())
  end function body_threads

end module contact_common
