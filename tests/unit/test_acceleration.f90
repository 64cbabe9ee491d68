!> Unit tests of the obstacles' update in the Robin iteration (module acceleration), on
!! affine fixed-point maps T(G) = M G + c whose fixed point G* = (I - M)^-1 c is computed
!! here by LAPACK (an independent reference):
!!  - relaxation: G + delta (T(G) - G), to the last bit;
!!  - Aitken (Irons-Tuck) on T = a I + c (every direction contracts alike): the first step
!!    relaxes by delta, the second lands on G* (exact for a scalar multiple of I: 1e-13);
!!    its factor stays in [-2, 2] on a map whose Irons-Tuck factor would leave that band;
!!  - Anderson on a general contraction of R^4 (two rows, two sides): with its history depth
!!    of 5 >= 4 it lands on G* within 6 updates (Anderson with a full history on a linear map
!!    is GMRES: 1e-12); on 6 unknowns (depth 5) it still converges faster than relaxation.
!! LAPACK's error handler (xerbla) is replaced here by one that counts: no call of the
!! module may hand LAPACK an illegal argument (Anderson with more stored differences than
!! unknowns once did: dgels's leading dimension below its columns).
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
module lapack_errors
  implicit none
  integer :: calls = 0   !< xerbla's calls
end module lapack_errors

!> LAPACK's error handler, counting instead of printing.
subroutine xerbla(srname, info)
  use lapack_errors, only: calls
  implicit none
  character(len=*), intent(in) :: srname
  integer, intent(in) :: info
  calls = calls + 1
  if (len(srname) < 0) calls = calls + info   ! (both arguments are LAPACK's)
end subroutine xerbla

program test_acceleration
  use kinds, only: wp
  use config, only: ACCEL_NONE, ACCEL_AITKEN, ACCEL_ANDERSON
  use contact_types, only: robin_state_t, state_init, ANDERSON_DEPTH
  use acceleration, only: accelerate
  use lapack, only: dgesv
  use testing, only: report, report_le, test_summary, set_seed, urand
  use lapack_errors, only: calls
  implicit none (type, external)

  call set_seed(20261129)
  call test_relaxation()
  call test_aitken()
  call test_anderson(2, 6, 1.0e-12_wp)
  call test_anderson_slower()
  call report(calls == 0, 'no LAPACK call with an illegal argument (xerbla not called)')
  call test_summary()

contains

  !> A random contraction of R^n with spectral radius below rho (a scaled random matrix).
  function contraction(n, rho) result(m)
    integer, intent(in) :: n
    real(wp), intent(in) :: rho
    real(wp) :: m(n, n), s
    integer :: i, j
    do j = 1, n
      do i = 1, n
        m(i, j) = urand(-1.0_wp, 1.0_wp)
      end do
    end do
    s = maxval(sum(abs(m), dim=2))   ! the infinity norm bounds the spectral radius
    m = m*(rho/s)
  end function contraction

  !> G* of T(G) = M G + c: (I - M) G* = c by LAPACK.
  function fixed_point(m, c) result(x)
    real(wp), intent(in) :: m(:, :), c(:)
    real(wp) :: x(size(c)), a(size(c), size(c))
    integer :: piv(size(c)), info, i
    a = -m
    do i = 1, size(c)
      a(i, i) = a(i, i) + 1.0_wp
    end do
    x = c
    call dgesv(size(c), 1, a, size(c), piv, x, size(c), info)
    if (info /= 0) error stop 'fixed_point: dgesv failed'
  end function fixed_point

  !> state%G and T(state%G) as (m, 2) arrays from the flat map on 2m unknowns.
  subroutine apply_map(m, c, st, g_new)
    real(wp), intent(in) :: m(:, :), c(:)
    type(robin_state_t), intent(in) :: st
    real(wp), intent(out) :: g_new(:, :)
    real(wp) :: x(size(c))
    x = reshape(st%G, [size(c)])
    g_new = reshape(matmul(m, x) + c, shape(g_new))
  end subroutine apply_map

  !> Plain relaxation: G + delta (T(G) - G), bit for bit.
  subroutine test_relaxation()
    type(robin_state_t) :: st
    real(wp) :: g_new(3, 2), t(3, 2), g0(3)
    g0 = [1.0_wp, -2.0_wp, 0.5_wp]
    call state_init(st, 3, g0, 2, 1)
    t = reshape([0.3_wp, 0.1_wp, -0.7_wp, 2.0_wp, 1.5_wp, 0.25_wp], [3, 2])
    g_new = t
    call accelerate(ACCEL_NONE, 0.5_wp, st, g_new)
    call report(all(g_new == st%G + 0.5_wp*(t - st%G)), 'relaxation: G + delta (T(G) - G), bit for bit')
  end subroutine test_relaxation

  !> Aitken on T(G) = a G + c: the first update relaxes by delta, the second lands on G*;
  !! its factor stays in [-2, 2].
  subroutine test_aitken()
    integer, parameter :: m = 3, n = 2*m
    type(robin_state_t) :: st
    real(wp) :: mm(n, n), c(n), xs(n), g_new(m, 2), g0(m), x0(n)
    integer :: i
    mm = 0.0_wp
    do i = 1, n
      mm(i, i) = -0.6_wp
      c(i) = urand(-1.0_wp, 1.0_wp)
    end do
    xs = fixed_point(mm, c)
    g0 = [0.1_wp, 0.2_wp, 0.3_wp]
    call state_init(st, m, g0, 2, 1)
    x0 = reshape(st%G, [n])
    call apply_map(mm, c, st, g_new)
    call accelerate(ACCEL_AITKEN, 0.5_wp, st, g_new)
    call report_le(maxval(abs(reshape(g_new, [n]) - (x0 + 0.5_wp*(matmul(mm, x0) + c - x0)))), 1.0e-15_wp, &
                   'Aitken: the first update relaxes by delta')
    st%G = g_new
    call apply_map(mm, c, st, g_new)
    call accelerate(ACCEL_AITKEN, 0.5_wp, st, g_new)
    call report_le(maxval(abs(reshape(g_new, [n]) - xs))/maxval(abs(xs)), 1.0e-13_wp, &
                   'Aitken: on T = a I + c the second update is the fixed point')
    ! a = 0.9 from omega = 0.5: Irons-Tuck would ask for 1/(1 - a) = 10; the band keeps 2
    mm = 0.0_wp
    do i = 1, n
      mm(i, i) = 0.9_wp
    end do
    call state_init(st, m, g0, 2, 1)
    do i = 1, 3
      call apply_map(mm, c, st, g_new)
      call accelerate(ACCEL_AITKEN, 0.5_wp, st, g_new)
      st%G = g_new
    end do
    call report(abs(st%omega) <= 2.0_wp .and. st%omega > 1.0_wp, 'Aitken: its factor kept in [-2, 2]')
  end subroutine test_aitken

  !> Anderson on a random contraction of R^(2m): within `steps` updates on the fixed point
  !! (depth >= 2m: GMRES on the affine map).
  subroutine test_anderson(m, steps, tol)
    integer, intent(in) :: m, steps
    real(wp), intent(in) :: tol
    type(robin_state_t) :: st
    real(wp) :: mm(2*m, 2*m), c(2*m), xs(2*m), g_new(m, 2), g0(m)
    integer :: k
    character(len=96) :: what
    mm = contraction(2*m, 0.8_wp)
    do k = 1, 2*m
      c(k) = urand(-1.0_wp, 1.0_wp)
    end do
    xs = fixed_point(mm, c)
    g0 = 0.0_wp
    call state_init(st, m, g0, 2, 1)
    call report(size(st%dX, 2) == ANDERSON_DEPTH .and. ANDERSON_DEPTH >= 2*m, 'Anderson: history depth covers the '// &
                'unknowns')
    do k = 1, steps + 4   ! (four more: past the history's depth)
      call apply_map(mm, c, st, g_new)
      call accelerate(ACCEL_ANDERSON, 0.5_wp, st, g_new)
      st%G = g_new
    end do
    write (what, '(a,i0,a,i0,a)') 'Anderson: on the fixed point of a contraction of R^', 2*m, ' within ', steps, ' updates'
    call report_le(maxval(abs(reshape(st%G, [2*m]) - xs))/maxval(abs(xs)), tol, trim(what))
  end subroutine test_anderson

  !> Six unknowns, depth 5: after 12 updates Anderson is closer to G* than relaxation by 0.5.
  subroutine test_anderson_slower()
    integer, parameter :: m = 3, n = 2*m
    type(robin_state_t) :: sa, sr
    real(wp) :: mm(n, n), c(n), xs(n), g_new(m, 2), g0(m), ea, er
    integer :: k
    mm = contraction(n, 0.9_wp)
    do k = 1, n
      c(k) = urand(-1.0_wp, 1.0_wp)
    end do
    xs = fixed_point(mm, c)
    g0 = 0.0_wp
    call state_init(sa, m, g0, 2, 1)
    call state_init(sr, m, g0, 2, 1)
    do k = 1, 12
      call apply_map(mm, c, sa, g_new)
      call accelerate(ACCEL_ANDERSON, 0.5_wp, sa, g_new)
      sa%G = g_new
      call apply_map(mm, c, sr, g_new)
      call accelerate(ACCEL_NONE, 0.5_wp, sr, g_new)
      sr%G = g_new
    end do
    ea = maxval(abs(reshape(sa%G, [n]) - xs))
    er = maxval(abs(reshape(sr%G, [n]) - xs))
    call report(ea < 1.0e-3_wp*er, 'Anderson (depth 5, 6 unknowns): a thousand times closer than relaxation after 12 updates')
  end subroutine test_anderson_slower

end program test_acceleration
