!> Text helpers shared by every stage: case folding, numbers to text (short round-trip
!! form for decks, fixed forms for messages and summary lines), namelist string literals,
!! blank-separated word lists, and the floating-point guard around READs of numbers.
!!
!! Numbers to text, one function a format: `i2s` (an integer), `roundtrip` (the shortest
!! text that reads back to a real: deck values), `sci` (scientific notation with a chosen
!! number of digits: measured values), `fixed` (fixed-point with a leading 0: sizes, times).
!!
!! Thread safety: gfortran 12 keeps the length of a deferred-length character function
!! result in a static variable of the call site, which two threads at the same statement
!! share (a wrong length, memory corrupted: seen in MPRGP under AddressSanitizer and in the
!! mesh reader). `i2s` and `sci` declare their result's length from their arguments, which
!! the caller computes into a local, so code that two threads run at once may call them;
!! `roundtrip`, `fixed`, `quote`, `word` and the others return deferred-length results and
!! are for serial code.
module strings
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: ieee_exceptions, only: ieee_usual, ieee_get_halting_mode, &
                                           ieee_set_halting_mode, ieee_get_flag, ieee_set_flag
  use kinds, only: wp
  implicit none (type, external)
  private

  public :: fpstate_t, fp_read_begin, fp_read_end, lower, is_ident, is_letter, first_nonblank
  public :: i2s, roundtrip, sci, fixed, quote, quoted_list, next_word, index_of, word

  !> Saved floating-point halting modes and flags.
  type :: fpstate_t
    logical :: halt(size(ieee_usual)) = .false.
    logical :: flag(size(ieee_usual)) = .false.
  end type fpstate_t

  !> Text built piece by piece in amortised linear time (the buffer doubles as it fills).
  type, public :: text_buffer_t
    character(len=:), allocatable :: buf   !< storage; the text is buf(1:n)
    integer :: n = 0                        !< characters in use
  contains
    procedure :: add => text_buffer_add    !< append a piece
    procedure :: text => text_buffer_text  !< the text so far
    !> the text so far into an allocatable (what code that two threads may run at once calls:
    !! no deferred-length function result, see the header)
    procedure :: get => text_buffer_get
  end type text_buffer_t

  !> Scientific notation with a 2- or 3-digit exponent as needed (1.234E-09, 1.798E+308):
  !! `sci(x)` with 3 digits after the point, `sci(x, digits)` with `digits`.
  interface sci
    module procedure sci_3, sci_digits
  end interface sci

contains

  subroutine text_buffer_add(self, piece)
    class(text_buffer_t), intent(inout) :: self
    character(len=*), intent(in) :: piece   !< text to append
    character(len=:), allocatable :: bigger
    if (.not. allocated(self%buf)) allocate (character(len=max(1024, 2*len(piece))) :: self%buf)
    if (self%n + len(piece) > len(self%buf)) then
      allocate (character(len=2*(self%n + len(piece))) :: bigger)
      bigger(1:self%n) = self%buf(1:self%n)
      call move_alloc(bigger, self%buf)
    end if
    self%buf(self%n + 1:self%n + len(piece)) = piece
    self%n = self%n + len(piece)
  end subroutine text_buffer_add

  function text_buffer_text(self) result(t)
    class(text_buffer_t), intent(in) :: self
    character(len=:), allocatable :: t
    call self%get(t)
  end function text_buffer_text

  subroutine text_buffer_get(self, t)
    class(text_buffer_t), intent(in) :: self
    character(len=:), allocatable, intent(out) :: t   !< the text so far
    if (allocated(self%buf)) then
      t = self%buf(1:self%n)
    else
      t = ''
    end if
  end subroutine text_buffer_get

  !> Disable floating-point halting around a READ (an overflowing literal such as 1e400
  !! would trap in a -ffpe-trap build; it is reported as non-finite instead).
  subroutine fp_read_begin(fp)
    type(fpstate_t), intent(out) :: fp
    call ieee_get_halting_mode(ieee_usual, fp%halt)
    call ieee_get_flag(ieee_usual, fp%flag)
    call ieee_set_halting_mode(ieee_usual, .false.)
  end subroutine fp_read_begin

  !> Restore the halting modes and exception flags saved by fp_read_begin.
  subroutine fp_read_end(fp)
    type(fpstate_t), intent(in) :: fp
    call ieee_set_flag(ieee_usual, fp%flag)
    call ieee_set_halting_mode(ieee_usual, fp%halt)
  end subroutine fp_read_end

  pure function lower(s) result(r)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: r
    integer :: i, c
    r = s
    do i = 1, len(s)
      c = iachar(s(i:i))
      if (c >= iachar('A') .and. c <= iachar('Z')) r(i:i) = achar(c + 32)
    end do
  end function lower

  pure logical function is_ident(c)
    character, intent(in) :: c
    is_ident = is_letter(c) .or. (c >= '0' .and. c <= '9') .or. c == '_'
  end function is_ident

  pure logical function is_letter(c)
    character, intent(in) :: c
    is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
  end function is_letter

  pure integer function first_nonblank(s)
    character(len=*), intent(in) :: s
    first_nonblank = max(1, verify(s, ' '))
  end function first_nonblank

  !> An integer as text, as short as it goes ('42', '-7'); its length is i2s_len(k), not
  !! deferred (code that two threads run may call it, see the header).
  pure function i2s(k) result(s)
    integer, intent(in) :: k   !< the integer
    character(len=i2s_len(k)) :: s
    write (s, '(i0)') k
  end function i2s

  !> The length of i2s(k): its digits and a minus sign (counted on -|k|, which never overflows).
  pure integer function i2s_len(k)
    integer, intent(in) :: k
    integer :: m
    if (k < 0) then
      i2s_len = 2
      m = k
    else
      i2s_len = 1
      m = -k
    end if
    do while (m <= -10)
      m = m / 10
      i2s_len = i2s_len + 1
    end do
  end function i2s_len

  !> A character value as a namelist string literal (quotes doubled).
  pure function quote(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    integer :: i
    r = ''''
    do i = 1, len(s)
      if (s(i:i) == '''') then
        r = r//''''''
      else
        r = r//s(i:i)
      end if
    end do
    r = r//''''
  end function quote

  !> 'a', 'b' or 'c' from a blank-separated list; with prefix '&': &a, &b, &c.
  function quoted_list(list, prefix) result(s)
    character(len=*), intent(in) :: list, prefix
    character(len=:), allocatable :: s
    integer :: p, q, n, k
    n = 0
    p = 1
    do while (p <= len(list))
      call next_word(list, p, q)
      if (q < p) exit
      n = n + 1
      p = q + 1
    end do
    s = ''
    do k = 1, n
      if (k > 1 .and. k < n) s = s//', '
      if (k > 1 .and. k == n) s = s//' or '
      if (prefix == '&') then
        s = s//'&'//word(list, k)
      else
        s = s//''''//word(list, k)//''''
      end if
    end do
  end function quoted_list

  !> The shortest text that reads back to exactly x: decimal form for exponents -3 to 5
  !! (0.001, 210000.0), else one digit before the point and an exponent (2.1e11); what the
  !! effective deck and messages about deck values print.
  function roundtrip(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=48) :: buf
    character(len=16) :: fmt
    character(len=:), allocatable :: digits, ip, fp
    integer :: d, ios, epos, e, k
    real(wp) :: y
    logical :: neg
    type(fpstate_t) :: fps

    if (.not. ieee_is_finite(x)) then
      write (buf, *) x
      s = trim(adjustl(buf))
      return
    end if
    if (x == 0.0_wp) then
      s = '0.0'
      return
    end if
    call fp_read_begin(fps)   ! a short rendering of a huge value may overflow when read
    do d = 1, 17
      write (fmt, '(a,i0,a)') '(es40.', d - 1, 'e4)'
      write (buf, fmt) x
      read (buf, *, iostat=ios) y
      if (ios == 0 .and. y == x) exit
    end do
    call fp_read_end(fps)
    buf = adjustl(buf)
    neg = buf(1:1) == '-'
    if (neg) buf = buf(2:)
    epos = index(buf, 'E')
    read (buf(epos + 1:), *) e
    digits = ''
    do k = 1, epos - 1
      if (buf(k:k) /= '.') digits = digits//buf(k:k)
    end do
    do while (len(digits) > 1)
      if (digits(len(digits):) /= '0') exit
      digits = digits(1:len(digits) - 1)
    end do
    if (e >= -3 .and. e <= 5) then
      if (e >= 0) then
        if (len(digits) <= e + 1) then
          ip = digits//repeat('0', e + 1 - len(digits))
          fp = '0'
        else
          ip = digits(1:e + 1)
          fp = digits(e + 2:)
        end if
      else
        ip = '0'
        fp = repeat('0', -e - 1)//digits
      end if
      s = ip//'.'//fp
    else
      if (len(digits) > 1) then
        s = digits(1:1)//'.'//digits(2:)//'e'//i2s(e)
      else
        s = digits//'.0e'//i2s(e)
      end if
    end if
    if (neg) s = '-'//s
  end function roundtrip

  !> Find the next blank-separated word at or after p: on return table(p:q) (q < p if none).
  subroutine next_word(table, p, q)
    character(len=*), intent(in) :: table
    integer, intent(inout) :: p
    integer, intent(out) :: q
    do while (p <= len(table))
      if (table(p:p) /= ' ') exit
      p = p + 1
    end do
    q = p - 1
    do while (q < len(table))
      if (table(q + 1:q + 1) == ' ') exit
      q = q + 1
    end do
  end subroutine next_word

  !> Position (1-based) of word `w` in a blank-separated list, 0 if absent.
  integer function index_of(list, w)
    character(len=*), intent(in) :: list, w
    integer :: p, q, k
    index_of = 0
    k = 0
    p = 1
    do while (p <= len(list))
      call next_word(list, p, q)
      if (q < p) exit
      k = k + 1
      if (lower(list(p:q)) == lower(w)) then
        index_of = k
        return
      end if
      p = q + 1
    end do
  end function index_of

  !> The k-th word of a blank-separated list.
  function word(list, k) result(w)
    character(len=*), intent(in) :: list
    integer, intent(in) :: k
    character(len=:), allocatable :: w
    integer :: p, q, j
    w = ''
    p = 1
    do j = 1, k
      call next_word(list, p, q)
      if (q < p) return
      if (j == k) w = list(p:q)
      p = q + 1
    end do
  end function word

  !> sci(x): 3 digits after the point.
  pure function sci_3(x) result(t)
    real(wp), intent(in) :: x   !< the value
    character(len=len_trim(sci_text(x, 3))) :: t
    t = sci_text(x, 3)
  end function sci_3

  !> sci(x, digits): `digits` digits after the point.
  pure function sci_digits(x, digits) result(t)
    real(wp), intent(in) :: x        !< the value
    integer, intent(in) :: digits    !< digits after the point
    character(len=len_trim(sci_text(x, digits))) :: t
    t = sci_text(x, digits)
  end function sci_digits

  !> sci's text, left-adjusted in a fixed-length buffer (its length is sci's result length).
  pure function sci_text(x, digits) result(buf)
    real(wp), intent(in) :: x
    integer, intent(in) :: digits
    character(len=32) :: buf
    character(len=32) :: fmt
    if (abs(x) >= 1.0e100_wp .or. (abs(x) < 1.0e-99_wp .and. x /= 0.0_wp)) then
      write (fmt, '(a,i0,a,i0,a)') '(es', digits + 8, '.', digits, 'e3)'
    else
      write (fmt, '(a,i0,a,i0,a)') '(es', digits + 7, '.', digits, ')'
    end if
    write (buf, fmt) x
    buf = adjustl(buf)
  end function sci_text

  !> Fixed-point text in format `fmt` ('(f0.2)', ...) with a leading 0 (0.95, 0.012);
  !! trailing zeros are dropped except for the format '(f0.3)' (times keep their three
  !! decimals).
  function fixed(x, fmt) result(s)
    real(wp), intent(in) :: x            !< the value
    character(len=*), intent(in) :: fmt  !< an F edit descriptor in parentheses
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
  end function fixed

end module strings
