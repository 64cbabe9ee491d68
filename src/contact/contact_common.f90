!> Small pieces every contact solver shares: the residual of an iterate on the contact
!! line, the other body's index, finiteness tests and the thread count for the two bodies.
module contact_common
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use condense, only: interface_t, body_condensed_t
  use contact_types, only: contact_result_t
  implicit none (type, external)
  private

  public :: interface_residual, other_body, maxabs, all_finite, body_threads

contains

  !> The body facing body a (1 <-> 2).
  pure integer function other_body(a)
    integer, intent(in) :: a   !< a body, 1 or 2
    other_body = 3 - a
  end function other_body

  !> Gap, imbalance, penetration, complementarity and equilibrium of res%lam_body, res%w.
  subroutine interface_residual(contact_line, bodies, res)
    type(interface_t), intent(in) :: contact_line         !< contact line
    type(body_condensed_t), intent(in) :: bodies(2)       !< condensed bodies (scales)
    type(contact_result_t), intent(inout) :: res          !< lam_body, w in; residuals out
    real(wp) :: uscale, lnorm, lmax
    integer :: i
    if (contact_line%m == 0) then
      res%residual = 0.0_wp
      return
    end if
    res%lam = 0.5_wp*(res%lam_body(:, 1) + res%lam_body(:, 2))
    res%gap = res%w(:, 1) + res%w(:, 2) - contact_line%g0
    uscale = max(maxabs(bodies(1)%b), maxabs(bodies(2)%b), maxabs(contact_line%g0), maxabs(res%w(:, 1)), &
                 maxabs(res%w(:, 2)), tiny(1.0_wp))
    lnorm = norm2(res%lam)
    lmax = maxval(res%lam)
    if (lnorm > 0.0_wp) then
      res%imbalance = norm2(res%lam_body(:, 1) - res%lam_body(:, 2))/lnorm
    else
      res%imbalance = 0.0_wp
    end if
    res%penetration = max(maxval(res%gap), 0.0_wp)/uscale
    res%complementarity = 0.0_wp
    if (lmax > 0.0_wp) then
      do i = 1, contact_line%m
        res%complementarity = max(res%complementarity, max(res%lam(i), 0.0_wp)*abs(res%gap(i)))
      end do
      res%complementarity = res%complementarity/(lmax*uscale)
    end if
    ! a floating body's equilibrium (its load against its own contact force): an inner
    ! solve that stopped on inner_max_it may leave it unmet, and then no run converges
    res%equilibrium = 0.0_wp
    do i = 1, 2
      if (bodies(i)%nrig == 0) cycle
      res%equilibrium = max(res%equilibrium, norm2(matmul(bodies(i)%rg, res%lam_body(:, i)) - bodies(i)%re)/ &
                            max(norm2(bodies(i)%re), merge(norm2(bodies(i)%rg)*norm2(res%lam_body(:, i)), 0.0_wp, &
                                all(bodies(i)%re == 0.0_wp)), tiny(1.0_wp)))
    end do
    res%residual = max(res%imbalance, res%penetration, res%complementarity, res%equilibrium)
    res%active = count(res%lam > 0.0_wp)
  end subroutine interface_residual

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

  !> Threads for the two bodies: min(2, OMP max threads).
  integer function body_threads()
    use omp_lib, only: omp_get_max_threads
    body_threads = max(1, min(2, omp_get_max_threads()))
  end function body_threads

end module contact_common
