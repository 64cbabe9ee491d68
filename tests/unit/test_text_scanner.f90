!> Tests of parse_real (module text_scanner) against the compiler's list-directed READ, the
!! independent reference: numbers written with 16 and 17 significant digits (what Gmsh
!! writes; beyond 2**53, parsed through 128-bit integers), short ones, 18 digits and large
!! exponents (the READ fallback), and halfway cases between two doubles; every value must be
!! the same double, bit for bit. Malformed tokens are refused. get_int gives parse_int's
!! value or refusal for every token, and counts the lines it passes.
program test_text_scanner
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: int64
  use text_scanner, only: parse_real, parse_int, get_int, scanner_t
  use errors, only: ERR_INPUT
  use testing, only: report, test_summary
  implicit none (type, external)
  character(len=40) :: t
  character(len=9), parameter :: fmts(4) = ['(es25.16)', '(es24.15)', '(es22.13)', '(es26.17)']
  real(wp) :: x, v, r
  integer(int64) :: seed
  integer :: k, f, nbad, ntried, e
  logical :: ok

  seed = 88172645463325252_int64
  do f = 1, size(fmts)
    nbad = 0
    ntried = 0
    do k = 1, 20000
      e = mod(k, 31) - 15
      x = (0.5_wp + uniform())*10.0_wp**e
      if (mod(k, 2) == 0) x = -x
      write (t, fmts(f)) x
      call parse_real(trim(adjustl(t)), v, ok)
      read (t, *) r
      ntried = ntried + 1
      if (.not. ok .or. transfer(v, 1_int64) /= transfer(r, 1_int64)) then
        if (nbad == 0) print '(a,a,2es26.17)', 'first mismatch: ', trim(t), v, r
        nbad = nbad + 1
      end if
    end do
    call report(nbad == 0, 'parse_real = READ bit for bit on 20000 numbers written '//trim(fmts(f)))
  end do

  ! halfway between two doubles: 1 + 2**-53 (ties to even: 1) and 1 + 3 2**-53 (up)
  call same('1.00000000000000011102230246251565404236316680908203125')
  call same('1.00000000000000033306690738754696212708950042724609375')
  call same('0.1')
  call same('-2.5e-3')
  call same('123456789012345678')
  call same('1.7976931348623157e308')
  call same('4.9406564584124654e-324')
  call same('6.02214076E+23')
  call parse_real('1.2.3', v, ok)
  call report(.not. ok, 'a malformed number is refused (1.2.3)')
  call parse_real('1e', v, ok)
  call report(.not. ok, 'a malformed number is refused (1e)')
  call test_get_int()
  call test_summary()

contains

  !> get_int on a text of integers: the values of parse_int, the line count; each token
  !! that parse_int refuses (too large, 19 digits, a letter, a lone sign) refused alike.
  subroutine test_get_int()
    character(len=*), parameter :: good(7) = [character(len=20) :: '12', '-7', '+3', &
                                              '000000000000000042', '2147483647', '-2147483647', '0']
    character(len=*), parameter :: bad(5) = [character(len=20) :: '2147483648', '0000000000000000007', &
                                             '12a', '-', '99999999999999999999']
    type(scanner_t) :: sc
    integer :: k, v, ref, nbad
    logical :: ok
    sc%text = '  12 '//achar(10)//'-7'//achar(9)//'+3 000000000000000042'//achar(13)//achar(10)// &
              '2147483647 -2147483647 0'
    sc%n = len(sc%text)
    sc%section = '$Test'
    nbad = 0
    do k = 1, size(good)
      v = get_int(sc, 'a number')
      call parse_int(trim(good(k)), ref, ok)
      if (.not. ok .or. v /= ref .or. sc%err%failed()) nbad = nbad + 1
    end do
    call report(nbad == 0 .and. sc%line == 3, 'get_int = parse_int on 7 tokens over 3 lines', real(nbad, wp))
    v = get_int(sc, 'a number')
    call report(sc%err%category == ERR_INPUT .and. index(sc%err%message, 'the file ends inside $Test') > 0, &
                'get_int at the end of the text: the file ends inside the section')
    nbad = 0
    do k = 1, size(bad)
      sc = scanner_t()
      sc%text = ' '//trim(bad(k))//' 5'
      sc%n = len(sc%text)
      sc%section = '$Test'
      v = get_int(sc, 'a number')
      call parse_int(trim(bad(k)), ref, ok)
      if (ok .or. sc%err%category /= ERR_INPUT .or. v /= 0 .or. index(sc%err%message, "found '"//trim(bad(k))//"'") == 0) nbad = nbad + 1
    end do
    call report(nbad == 0, 'get_int refuses what parse_int refuses, naming the token (5 tokens)', real(nbad, wp))
  end subroutine test_get_int

  !> A uniform number in [0, 1) from a 64-bit xorshift.
  real(wp) function uniform()
    seed = ieor(seed, ishft(seed, 13))
    seed = ieor(seed, ishft(seed, -7))
    seed = ieor(seed, ishft(seed, 17))
    uniform = real(ishft(seed, -11), wp)*2.0_wp**(-53)
  end function uniform

  subroutine same(s)
    character(len=*), intent(in) :: s
    real(wp) :: a, b
    logical :: good
    call parse_real(s, a, good)
    read (s, *) b
    call report(good .and. transfer(a, 1_int64) == transfer(b, 1_int64), 'parse_real = READ for '//s)
  end subroutine same
end program test_text_scanner
