!> robin_contact: frictionless contact between two elastic bodies by a Robin
!! (Lions-type) nonoverlapping domain decomposition (Sassi, Ipopa, Roux).
!!
!! Usage: robin_contact DECK.nml ['&group var=value ... /' ...]
!! Exit codes: 0 converged, 1 bad input or usage, 2 did not converge,
!! 3 numerical failure, 4 interrupted (checkpoint written).
program robin_contact
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use errors, only: fatal, terminate, EXIT_OK, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_NUMERICAL
  use config, only: deck_t
  use deck, only: read_deck, print_deck, deck_usage
  use mesh, only: mesh_t, mesh_build
  use assembly, only: body_system_t, assemble_body, expand
  use condense, only: interface_t, body_condensed_t, build_interface, factor_body, condense_body, &
                      recover_displacement
  use contact, only: contact_result_t, solve_robin, solve_monolithic
  use results, only: timing_t, write_results, program_version
  use sysinfo, only: peak_rss_mb
  use omp_lib, only: omp_get_wtime, omp_get_max_threads
  implicit none

  type(deck_t) :: d
  type(mesh_t) :: msh(2)
  type(body_system_t) :: sys(2)
  type(interface_t) :: itf
  type(body_condensed_t) :: bc(2)
  type(contact_result_t) :: res
  type(timing_t) :: tm
  character(len=:), allocatable :: deck_path
  character(len=4096), allocatable :: overrides(:)
  character(len=512) :: msg(2), msg1
  integer :: info(2), info1, a, nthr, code, maxndof
  real(wp) :: t_start, t0
  real(wp), allocatable :: u(:, :), ufree(:)
  logical :: ok

  t_start = omp_get_wtime()
  call parse_arguments(deck_path, overrides)
  call read_deck(deck_path, overrides, d)
  write (output_unit, '(a)') 'robin_contact '//program_version//': effective input'
  call print_deck(d, output_unit)
  nthr = max(1, min(2, omp_get_max_threads()))

  ! ---- assemble both bodies --------------------------------------------------------
  t0 = omp_get_wtime()
  !$omp parallel do num_threads(nthr) schedule(static, 1)
  do a = 1, 2
    call mesh_build(msh(a), d%body(a))
    call assemble_body(msh(a), d%body(a), d%plane_strain, d%traction, d%ntraction, sys(a), info(a), msg(a))
  end do
  !$omp end parallel do
  do a = 1, 2
    if (info(a) /= 0) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//', body '//achar(48 + a)//': '//trim(msg(a)))
  end do
  call build_interface(d, msh, sys, itf, info1, msg1)
  if (info1 /= 0) call fatal(EXIT_INPUT, 'deck '//trim(d%source)//': '//trim(msg1))
  tm%assemble = omp_get_wtime() - t0
  write (output_unit, '(a,i0,a,i0,a,i0,a,i0)') 'assembled: n1=', sys(1)%n, ' n2=', sys(2)%n, &
    ' m=', itf%m, ' threads=', nthr

  ! ---- factorize and condense (one thread per body) -------------------------------
  t0 = omp_get_wtime()
  !$omp parallel do num_threads(nthr) schedule(static, 1)
  do a = 1, 2
    call factor_body(d, itf, a, sys(a), bc(a), info(a), msg(a))
  end do
  !$omp end parallel do
  do a = 1, 2
    if (info(a) /= 0) call fatal(EXIT_NUMERICAL, 'body '//achar(48 + a)//': factorization failed: '//trim(msg(a)))
  end do
  tm%factor = omp_get_wtime() - t0
  t0 = omp_get_wtime()
  !$omp parallel do num_threads(nthr) schedule(static, 1)
  do a = 1, 2
    call condense_body(sys(a), bc(a), info(a), msg(a))
  end do
  !$omp end parallel do
  do a = 1, 2
    if (info(a) /= 0) call fatal(EXIT_NUMERICAL, 'body '//achar(48 + a)//': condensation failed: '//trim(msg(a)))
  end do
  tm%condense = omp_get_wtime() - t0
  tm%factor_mb = (bc(1)%chol%mem_bytes + bc(2)%chol%mem_bytes)/1048576.0_wp

  ! ---- contact ----------------------------------------------------------------------
  t0 = omp_get_wtime()
  if (d%solver%method == 'monolithic') then
    call solve_monolithic(d, itf, bc, res)
  else
    call solve_robin(d, itf, bc, res, output_unit)
  end if
  ! displacements of both bodies under their own contact forces
  maxndof = max(sys(1)%ndof, sys(2)%ndof)
  allocate (u(maxndof, 2))
  u = 0.0_wp
  if (res%status /= 'failed') then
    !$omp parallel do num_threads(nthr) schedule(static, 1) private(ufree)
    do a = 1, 2
      allocate (ufree(sys(a)%n))
      call recover_displacement(sys(a), bc(a), res%lam_body(:, a), ufree)
      call expand(sys(a), ufree, u(1:sys(a)%ndof, a))
      deallocate (ufree)
    end do
    !$omp end parallel do
  end if
  tm%iterate = omp_get_wtime() - t0

  select case (trim(res%status))
  case ('converged')
    code = EXIT_OK
  case ('failed')
    code = EXIT_NUMERICAL
  case default
    code = EXIT_NOT_CONVERGED
  end select
  if (res%status /= 'converged') write (error_unit, '(a)') 'robin_contact: '//trim(res%status)//': '//trim(res%message)

  ! ---- output -------------------------------------------------------------------------
  t0 = omp_get_wtime()
  if (code /= EXIT_NUMERICAL) then
    tm%peak_rss_mb = peak_rss_mb()
    tm%total = omp_get_wtime() - t_start
    call write_results(d%output%file, d, msh, sys, itf, res, u, tm, ok, msg1)
    if (.not. ok) call fatal(EXIT_NUMERICAL, 'output: '//trim(msg1))
  end if
  tm%output = omp_get_wtime() - t0
  tm%total = omp_get_wtime() - t_start
  tm%peak_rss_mb = peak_rss_mb()
  call summary()
  call terminate(code)

contains

  subroutine summary()
    real(wp) :: ftot
    ftot = 0.0_wp
    if (itf%m > 0) ftot = sum(res%lam)
    write (output_unit, '(a,es12.5,a,i0,a,es10.3,a,es10.3,a,es10.3)') 'contact: total normal force=', ftot, &
      ' active=', res%active, ' imbalance=', res%imbalance, ' penetration=', res%penetration, &
      ' complementarity=', res%complementarity
    if (code /= EXIT_NUMERICAL) write (output_unit, '(a)') 'output: '//trim(d%output%file)
    write (output_unit, '(a,6(a,f0.3),a,f0.1,a,f0.1)') 'time:', ' assemble=', tm%assemble, ' factor=', tm%factor, &
      ' condense=', tm%condense, ' iterate=', tm%iterate, ' output=', tm%output, ' total=', tm%total, &
      ' peak_mb=', tm%peak_rss_mb, ' factor_mb=', tm%factor_mb
    write (output_unit, '(a,a,a,a,a,i0,a,i0,a,i0,a,i0,a,i0,a,a,a,es8.2,a,a)') 'result: status=', trim(res%status), &
      ' method=', trim(res%method), ' outer=', res%outer, ' inner=', res%inner, ' n1=', sys(1)%n, &
      ' n2=', sys(2)%n, ' m=', itf%m, ' delta=', fmt_real(d%solver%delta, '(f0.6)'), ' residual=', res%residual, &
      ' wall_s=', fmt_real(tm%total, '(f0.3)')
  end subroutine summary

  !> A fixed-point number without trailing zeros and with a leading 0 (0.95, 1, 0.012).
  function fmt_real(x, fmt) result(s)
    real(wp), intent(in) :: x
    character(len=*), intent(in) :: fmt
    character(len=:), allocatable :: s
    character(len=40) :: buf
    write (buf, fmt) x
    s = trim(adjustl(buf))
    if (index(s, '.') > 0 .and. fmt /= '(f0.3)') then
      do while (s(len(s):len(s)) == '0')
        s = s(1:len(s) - 1)
      end do
      if (s(len(s):len(s)) == '.') s = s(1:len(s) - 1)
    end if
    if (s(1:1) == '.') s = '0'//s
  end function fmt_real

  subroutine parse_arguments(path, extra)
    character(len=:), allocatable, intent(out) :: path
    character(len=4096), allocatable, intent(out) :: extra(:)
    integer :: n, i, l
    character(len=4096) :: arg
    n = command_argument_count()
    if (n < 1) call fatal(EXIT_INPUT, 'no deck file given'//achar(10)//deck_usage)
    call get_command_argument(1, arg, l)
    if (trim(arg) == '-h' .or. trim(arg) == '--help') then
      write (output_unit, '(a)') deck_usage
      call terminate(EXIT_OK)
    end if
    path = trim(arg)
    allocate (extra(n - 1))
    do i = 2, n
      call get_command_argument(i, extra(i - 1), l)
      if (l > len(extra(i - 1))) call fatal(EXIT_INPUT, 'command-line argument too long')
    end do
  end subroutine parse_arguments

end program robin_contact
