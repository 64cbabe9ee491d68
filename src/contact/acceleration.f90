!> The update of the obstacles in the Robin iteration: relaxation by delta, Aitken
!! (Irons-Tuck) dynamic relaxation, or Anderson mixing of the fixed-point map
!! G -> T(G) (doc/method.md, "Method as implemented").
module acceleration
  use kinds, only: wp
  use config, only: ACCEL_AITKEN, ACCEL_ANDERSON
  use lapack, only: dgels
  use contact_types, only: robin_state_t
  use contact_common, only: all_finite
  implicit none (type, external)
  private

  public :: accelerate

contains

  !> Relaxed or accelerated fixed-point update: on entry g_new = T(G), on exit the next
  !! obstacles. The residual of the fixed point is r = T(G) - G.
  subroutine accelerate(kind, delta, state, g_new)
    integer, intent(in) :: kind                      !< ACCEL_*
    real(wp), intent(in) :: delta                    !< relaxation (Anderson: mixing) parameter
    type(robin_state_t), intent(inout) :: state      !< G, and the acceleration's history
    real(wp), intent(inout) :: g_new(:, :)           !< (m, 2) T(G) in, next obstacles out
    real(wp), allocatable :: x(:), r(:)
    integer :: n2
    n2 = 2*size(g_new, 1)
    allocate (x(n2), r(n2))
    x = reshape(state%G, [n2])
    r = reshape(g_new, [n2]) - x
    select case (kind)
    case (ACCEL_AITKEN)
      call aitken(delta, state, x, r)
    case (ACCEL_ANDERSON)
      call anderson(delta, state, x, r)
    case default
      x = x + delta*r
    end select
    g_new = reshape(x, shape(g_new))
  end subroutine accelerate

  !> Irons-Tuck: omega_k = -omega_{k-1} r_{k-1}'(r_k - r_{k-1}) / |r_k - r_{k-1}|^2, kept in
  !! a safe band; x <- x + omega_k r.
  subroutine aitken(delta, state, x, r)
    real(wp), intent(in) :: delta
    type(robin_state_t), intent(inout) :: state
    real(wp), intent(inout) :: x(:)
    real(wp), intent(in) :: r(:)
    real(wp), allocatable :: dr(:)
    real(wp) :: den
    if (state%nacc == 0) then
      state%omega = delta
    else
      allocate (dr(size(r)))
      dr = r - state%r_prev
      den = dot_product(dr, dr)
      if (den > 0.0_wp) then
        state%omega = -state%omega*dot_product(state%r_prev, dr)/den
        state%omega = max(-2.0_wp, min(2.0_wp, state%omega))
        if (abs(state%omega) < 1.0e-3_wp) state%omega = sign(1.0e-3_wp, state%omega)
      end if
    end if
    state%r_prev = r
    state%nacc = state%nacc + 1
    x = x + state%omega*r
  end subroutine aitken

  !> Anderson mixing of the state's depth (its stored differences, `anderson_history`, at
  !! most the 2m unknowns) with mixing parameter delta:
  !! x+ = x + delta r - (dX + delta dR) gamma, gamma = argmin |r - dR gamma|.
  subroutine anderson(delta, state, x, r)
    real(wp), intent(in) :: delta
    type(robin_state_t), intent(inout) :: state
    real(wp), intent(inout) :: x(:)
    real(wp), intent(in) :: r(:)
    real(wp), allocatable :: gam(:), qr(:, :), rhs(:), work(:)
    integer :: n2, k, j, info, lwork, depth
    n2 = size(x)
    ! at most n2 differences: more would make the least-squares problem underdetermined
    ! (and LAPACK's dgels refuses a leading dimension below the columns)
    depth = min(size(state%dX, 2), n2)
    if (state%nacc > 0) then
      j = mod(state%nacc - 1, depth) + 1
      state%dX(:, j) = x - state%x_prev
      state%dR(:, j) = r - state%r_prev
    end if
    state%x_prev = x
    state%r_prev = r
    k = min(state%nacc, depth)
    state%nacc = state%nacc + 1
    if (k > 0) then
      allocate (qr(n2, k), rhs(n2), gam(k))
      qr = state%dR(:, 1:k)
      rhs = r
      lwork = -1
      allocate (work(1))
      call dgels('N', n2, k, 1, qr, n2, rhs, n2, work, lwork, info)
      lwork = max(1, int(work(1)))
      deallocate (work)
      allocate (work(lwork))
      call dgels('N', n2, k, 1, qr, n2, rhs, n2, work, lwork, info)
      if (info == 0 .and. all_finite(rhs(1:k))) then
        gam = rhs(1:k)
        x = x + delta*r - matmul(state%dX(:, 1:k) + delta*state%dR(:, 1:k), gam)
      else
        x = x + delta*r
      end if
    else
      x = x + delta*r
    end if
  end subroutine anderson

end module acceleration
