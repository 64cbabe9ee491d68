!> A text scanner over a whole file held in memory: blank-separated tokens, integers and
!! reals converted by hand (a list-directed READ costs about 1.7 us a number, several
!! seconds for the millions of numbers of a large mesh file), the current line for
!! messages, and the first error met (an error_t: ERR_INPUT or ERR_MEMORY and its sentence,
!! with its line). After an error every read returns at once (0 for a number), so a reader
!! checks `scanner%err%failed()` only where it must stop. The end of the text is no error: a
!! token starting past the end (s > scanner%n) says so, and the reader that expected one
!! more reports it (bad_token, expect).
module text_scanner
  use kinds, only: wp, i8
  use errors, only: error_t, ERR_NONE, ERR_INPUT, ERR_MEMORY
  use strings, only: i2s, fpstate_t, fp_read_begin, fp_read_end
  implicit none (type, external)
  private

  public :: scanner_load, scan_fail, next_token, bad_token, get_int, get_real, read_count, bytes_left, &
            expect, skip_past, parse_int, parse_real

  integer, parameter :: i16 = selected_int_kind(38)   ! 128-bit integers (nearest_quotient)

  real(wp), parameter :: p10(0:22) = [ &   ! the powers of ten that doubles hold exactly
    1.0e0_wp, 1.0e1_wp, 1.0e2_wp, 1.0e3_wp, 1.0e4_wp, 1.0e5_wp, 1.0e6_wp, 1.0e7_wp, 1.0e8_wp, &
    1.0e9_wp, 1.0e10_wp, 1.0e11_wp, 1.0e12_wp, 1.0e13_wp, 1.0e14_wp, 1.0e15_wp, 1.0e16_wp, &
    1.0e17_wp, 1.0e18_wp, 1.0e19_wp, 1.0e20_wp, 1.0e21_wp, 1.0e22_wp]

  !> The file's text and a reading position, with the first error met.
  type, public :: scanner_t
    character(len=:), allocatable :: text     !< the whole file
    integer(i8) :: n = 0                      !< its length
    integer(i8) :: pos = 1                    !< next character
    integer :: line = 1                       !< the line of pos
    character(len=:), allocatable :: path     !< the file
    character(len=:), allocatable :: section  !< the part being read, for messages
    type(error_t) :: err                      !< the first error: ERR_INPUT (bad text) or ERR_MEMORY, its sentence
    integer :: err_line = 0                   !< its line (0: none)
  end type scanner_t

contains

  ! ---- errors ---------------------------------------------------------------------------

  !> Record an error (the first one only) at the current line, or with no line (at_line false).
  subroutine scan_fail(scanner, text, category, at_line)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: text               !< what is wrong (the reader adds file and line)
    integer, intent(in), optional :: category          !< ERR_INPUT (default) or ERR_MEMORY
    logical, intent(in), optional :: at_line           !< .false.: the error has no line
    if (scanner%err%category /= ERR_NONE) return
    ! the components set directly (no trim): readers of several bodies run this on threads
    scanner%err%category = ERR_INPUT
    if (present(category)) scanner%err%category = category
    scanner%err_line = scanner%line
    if (present(at_line)) then
      if (.not. at_line) scanner%err_line = 0
    end if
    scanner%err%message = text
  end subroutine scan_fail

  ! ---- the text -------------------------------------------------------------------------

  !> Read the whole file `path` into scanner%text (scanner%path names it in messages).
  subroutine scanner_load(scanner, path)
    type(scanner_t), intent(inout) :: scanner   !< the scanner, at the file's start on return
    character(len=*), intent(in) :: path    !< the file
    integer :: u, ios, st
    integer(i8) :: size_bytes
    character(len=256) :: iom

    scanner%path = path
    scanner%section = ''
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios, iomsg=iom)
    if (ios /= 0) then
      call scan_fail(scanner, 'cannot be opened ('//trim(iom)//')', at_line=.false.)
      return
    end if
    inquire (unit=u, size=size_bytes)
    if (size_bytes <= 0) then
      close (u)
      call scan_fail(scanner, 'is empty or not a regular file', at_line=.false.)
      return
    end if
    allocate (character(len=size_bytes) :: scanner%text, stat=st)
    if (st /= 0) then
      close (u)
      call scan_fail(scanner, 'needs '//i2s(int(size_bytes/2**20))//' MB of memory to be read', &
                ERR_MEMORY, .false.)
      return
    end if
    read (u, iostat=ios, iomsg=iom) scanner%text
    close (u)
    if (ios /= 0) then
      call scan_fail(scanner, 'cannot be read ('//trim(iom)//')', at_line=.false.)
      return
    end if
    scanner%n = size_bytes
    ! a UTF-8 byte-order mark (written by some editors) is not part of the text
    if (size_bytes >= 3) then
      if (iachar(scanner%text(1:1)) == 239 .and. iachar(scanner%text(2:2)) == 187 .and. &
          iachar(scanner%text(3:3)) == 191) scanner%pos = 4
    end if
  end subroutine scanner_load

  !> The next token (characters above the blank) as text(s:e); s > scanner%n at the end of the
  !! file. Blanks, tabs, carriage returns and other control characters separate tokens.
  subroutine next_token(scanner, s, e)
    type(scanner_t), intent(inout) :: scanner
    integer(i8), intent(out) :: s, e
    integer(i8) :: pos
    pos = skip_blanks(scanner, scanner%pos)   ! in locals: the loops keep them in registers
    s = pos
    do while (pos <= scanner%n)
      if (iachar(scanner%text(pos:pos)) <= 32) exit
      pos = pos + 1
    end do
    e = pos - 1
    scanner%pos = pos
  end subroutine next_token

  !> The first position from pos on that holds neither a blank nor a control character
  !! (n + 1 at the end), counting the line feeds passed.
  integer(i8) function skip_blanks(scanner, pos0) result(pos)
    type(scanner_t), intent(inout) :: scanner
    integer(i8), intent(in) :: pos0
    integer :: code
    pos = pos0
    do while (pos <= scanner%n)
      code = iachar(scanner%text(pos:pos))
      if (code > 32) exit
      if (code == 10) scanner%line = scanner%line + 1
      pos = pos + 1
    end do
  end function skip_blanks

  !> Report the end of the file inside a section, or a token that is not `what`.
  subroutine bad_token(scanner, s, e, what)
    type(scanner_t), intent(inout) :: scanner
    integer(i8), intent(in) :: s, e
    character(len=*), intent(in) :: what
    if (s > scanner%n) then
      call scan_fail(scanner, 'the file ends inside '//scanner%section//' where '//what// &
                ' was expected (truncated file?)')
    else
      call scan_fail(scanner, 'expected '//what//' in '//scanner%section//", found '"// &
                scanner%text(s:min(e, s + 40))//"'")
    end if
  end subroutine bad_token

  !> The next token as an integer (0 after an error). A token of 1 to 18 digits is
  !! converted as it is scanned; any other goes through next_token and parse_int (the
  !! same value, or the same refusal).
  integer function get_int(scanner, what) result(v)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: what   ! what the number is, for messages
    integer(i8) :: s, e, pos, m
    integer :: code, d
    logical :: ok
    v = 0
    if (scanner%err%category /= ERR_NONE) return
    pos = skip_blanks(scanner, scanner%pos)
    scanner%pos = pos
    m = 0
    do while (pos <= scanner%n)
      code = iachar(scanner%text(pos:pos))
      if (code <= 32) exit
      d = code - iachar('0')
      if (d < 0 .or. d > 9 .or. pos - scanner%pos >= 18) then
        m = -1
        exit
      end if
      m = 10*m + d
      pos = pos + 1
    end do
    if (m >= 0 .and. pos > scanner%pos .and. m <= huge(v)) then
      v = int(m)
      scanner%pos = pos
      return
    end if
    call next_token(scanner, s, e)
    ok = s <= e
    if (ok) call parse_int(scanner%text(s:e), v, ok)
    if (.not. ok) call bad_token(scanner, s, e, what//' (an integer)')
  end function get_int

  !> The next token as a real (0 after an error).
  real(wp) function get_real(scanner, what) result(v)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: what
    integer(i8) :: s, e
    logical :: ok
    v = 0.0_wp
    if (scanner%err%category /= ERR_NONE) return
    call next_token(scanner, s, e)
    ok = s <= e
    if (ok) call parse_real(scanner%text(s:e), v, ok)
    if (.not. ok) call bad_token(scanner, s, e, what//' (a finite real)')
  end function get_real

  !> The next token as a count of items that follow in the file (0 after an error): a
  !! non-negative integer. Every count that sizes an allocation is read here. With
  !! `min_bytes` (the fewest characters one item takes in the file, its separators included)
  !! and `items` (the items' name, plural), the count is checked in 64-bit arithmetic
  !! against the characters left, so that no count the file cannot hold sizes an allocation.
  integer function read_count(scanner, what, min_bytes, items) result(v)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: what                 ! what is counted, for messages
    integer, intent(in), optional :: min_bytes           ! the fewest characters of one item
    character(len=*), intent(in), optional :: items      ! the items, plural ('nodes')
    integer(i8) :: s, e
    logical :: ok
    v = 0
    if (scanner%err%category /= ERR_NONE) return
    call next_token(scanner, s, e)
    ok = s <= e
    if (ok) call parse_int(scanner%text(s:e), v, ok)
    if (ok) ok = v >= 0
    if (.not. ok) then
      v = 0
      call bad_token(scanner, s, e, what//' (an integer >= 0)')
      return
    end if
    if (present(min_bytes)) then
      if (int(v, i8)*min_bytes > bytes_left(scanner)) then
        if (present(items)) then
          call scan_fail(scanner, scanner%section//' announces '//i2s(v)//' '//items// &
                         ', but the rest of the file holds at most '//i8s(bytes_left(scanner))// &
                         ' bytes, room for at most '//i8s(bytes_left(scanner)/min_bytes)// &
                         ' (one takes at least '//i2s(min_bytes)//' bytes; truncated file?)')
        else
          call scan_fail(scanner, what//' in '//scanner%section//' is '//i2s(v)// &
                         ', but the rest of the file holds at most '//i8s(bytes_left(scanner))//' bytes')
        end if
        v = 0
      end if
    end if
  end function read_count

  !> A 64-bit integer as text.
  pure function i8s(k) result(t)
    integer(i8), intent(in) :: k
    character(len=:), allocatable :: t
    character(len=24) :: buf
    write (buf, '(i0)') k
    t = trim(buf)
  end function i8s

  !> The characters from the position to the end of the file.
  pure integer(i8) function bytes_left(scanner)
    type(scanner_t), intent(in) :: scanner
    bytes_left = max(scanner%n - scanner%pos + 1, 0_i8)
  end function bytes_left

  !> The next token must be `word` (a section's end marker).
  subroutine expect(scanner, word)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: word
    integer(i8) :: s, e
    if (scanner%err%category /= ERR_NONE) return
    call next_token(scanner, s, e)
    if (s > scanner%n) then
      call scan_fail(scanner, 'the file ends before '//word//' (truncated file?)')
    else if (scanner%text(s:e) /= word) then
      call scan_fail(scanner, 'expected '//word//" to close "//scanner%section//", found '"// &
                scanner%text(s:min(e, s + 40))//"'")
    end if
  end subroutine expect

  !> Move past the first `marker` at or after the position (the end of a section that is
  !! not read).
  subroutine skip_past(scanner, marker)
    type(scanner_t), intent(inout) :: scanner
    character(len=*), intent(in) :: marker   !< e.g. '$EndComments'
    integer(i8) :: k, stop_at
    k = index(scanner%text(scanner%pos:scanner%n), marker, kind=i8)
    if (k == 0) then
      call scan_fail(scanner, 'the file ends before '//marker//' (truncated file?)')
      return
    end if
    stop_at = scanner%pos + k - 1
    do while (scanner%pos < stop_at)
      if (scanner%text(scanner%pos:scanner%pos) == achar(10)) scanner%line = scanner%line + 1
      scanner%pos = scanner%pos + 1
    end do
    scanner%pos = stop_at + len(marker)
  end subroutine skip_past

  !> A decimal integer with an optional sign, in the default integer range. A token that
  !! is not one is an answer (valid false), not a failure: the caller names the token.
  pure subroutine parse_int(t, v, valid)
    character(len=*), intent(in) :: t   !< the token
    integer, intent(out) :: v           !< its value (0 when not valid)
    logical, intent(out) :: valid       !< t is such an integer
    integer :: i, i0, d
    integer(i8) :: m
    v = 0
    i0 = 1
    if (t(1:1) == '-' .or. t(1:1) == '+') i0 = 2
    valid = len(t) >= i0 .and. len(t) - i0 < 18
    if (.not. valid) return
    m = 0
    do i = i0, len(t)
      d = iachar(t(i:i)) - iachar('0')
      if (d < 0 .or. d > 9) then
        valid = .false.
        return
      end if
      m = 10*m + d
    end do
    if (t(1:1) == '-') m = -m
    valid = abs(m) <= huge(v)
    if (valid) v = int(m)
  end subroutine parse_int

  !> A decimal real: an optional sign, digits with an optional fraction (one digit at least)
  !! and an optional exponent (e, E, d or D). Exact (correctly rounded): with a mantissa below
  !! 2**53 and a power of ten up to 22 by one multiplication or division of two exact
  !! doubles; with up to 17 significant digits and a power of ten from -21 to 20 by
  !! nearest_quotient; other forms (18+ digits, large exponents) by a formatted READ. A
  !! token that is not a finite real is an answer (valid false), not a failure.
  subroutine parse_real(t, v, valid)
    character(len=*), intent(in) :: t   !< the token
    real(wp), intent(out) :: v          !< its value
    logical, intent(out) :: valid       !< t is a finite real
    integer :: i, d, nsig, e10, ex, esign
    integer(i8) :: m
    logical :: digits, neg
    type(fpstate_t) :: fp
    integer :: ios

    v = 0.0_wp
    i = 1
    neg = t(1:1) == '-'
    if (t(1:1) == '-' .or. t(1:1) == '+') i = 2
    m = 0
    nsig = 0
    e10 = 0
    digits = .false.
    valid = .true.
    do while (i <= len(t))                       ! integer part
      d = iachar(t(i:i)) - iachar('0')
      if (d < 0 .or. d > 9) exit
      digits = .true.
      if (nsig >= 18) then
        valid = .false.
      else
        m = 10*m + d
        if (m > 0) nsig = nsig + 1
      end if
      i = i + 1
    end do
    if (i <= len(t)) then                        ! fraction
      if (t(i:i) == '.') then
        i = i + 1
        do while (i <= len(t))
          d = iachar(t(i:i)) - iachar('0')
          if (d < 0 .or. d > 9) exit
          digits = .true.
          if (nsig >= 18) then
            valid = .false.
          else
            m = 10*m + d
            if (m > 0) nsig = nsig + 1
            e10 = e10 - 1
          end if
          i = i + 1
        end do
      end if
    end if
    if (i <= len(t)) then                        ! exponent
      if (t(i:i) == 'e' .or. t(i:i) == 'E' .or. t(i:i) == 'd' .or. t(i:i) == 'D') then
        i = i + 1
        esign = 1
        if (i <= len(t)) then
          if (t(i:i) == '-') esign = -1
          if (t(i:i) == '-' .or. t(i:i) == '+') i = i + 1
        end if
        ex = 0
        digits = digits .and. i <= len(t)
        do while (i <= len(t))
          d = iachar(t(i:i)) - iachar('0')
          if (d < 0 .or. d > 9) exit
          if (ex < 100000) ex = 10*ex + d
          i = i + 1
        end do
        e10 = e10 + esign*ex
      end if
    end if
    ! the form: digits, and nothing after the exponent ('+', '.', '1-2' are no numbers)
    if (.not. (digits .and. i > len(t))) then
      valid = .false.
      return
    end if
    if (valid .and. m == 0) then
      v = 0.0_wp
    else if (valid .and. m <= 2_i8**53 .and. abs(e10) <= 22) then
      v = real(m, wp)
      if (e10 >= 0) then
        v = v*p10(e10)
      else
        v = v/p10(-e10)
      end if
    else if (valid .and. e10 >= -21 .and. e10 <= 20) then
      v = nearest_quotient(int(m, i16)*10_i16**max(e10, 0), 10_i16**max(-e10, 0))
    else
      ! Rare forms (18+ digits, large exponents): a formatted READ, only of number
      ! characters (a list-directed READ would take '/' or ',' as separators).
      valid = len(t) <= 64 .and. verify(t, '0123456789+-.eEdD') == 0
      if (.not. valid) return
      call fp_read_begin(fp)
      read (t, '(f64.0)', iostat=ios) v
      call fp_read_end(fp)
      valid = ios == 0 .and. abs(v) <= huge(v)
      return
    end if
    if (neg) v = -v
  end subroutine parse_real

  !> The double nearest to num/den (ties to even), num, den > 0 and num/den a normal
  !! double, den < 2**72: the 54-bit quotient num 2**s / den, in 128-bit integers, rounded
  !! to 53 bits with the remainder as the sticky bit. Gmsh writes 16 and 17 significant
  !! digits, beyond the 2**53 of the exact product in parse_real.
  pure real(wp) function nearest_quotient(num, den) result(v)
    integer(i16), intent(in) :: num, den
    integer(i16) :: q, r, d
    integer :: s
    s = 54 - (bit_size_of(num) - bit_size_of(den))
    do
      if (s >= 0) then
        q = (num*2_i16**s)/den
        r = num*2_i16**s - q*den
      else
        d = den*2_i16**(-s)
        q = num/d
        r = num - q*d
      end if
      if (q >= 2_i16**54) then
        s = s - 1
      else if (q < 2_i16**53) then
        s = s + 1
      else
        exit
      end if
    end do
    ! q: 53 bits and a rounding bit
    if (btest(q, 0) .and. (r /= 0 .or. btest(q, 1))) then
      q = q/2 + 1
    else
      q = q/2
    end if
    v = scale(real(q, wp), 1 - s)
  end function nearest_quotient

  !> The number of bits of x > 0.
  pure integer function bit_size_of(x) result(n)
    integer(i16), intent(in) :: x
    n = int(bit_size(x)) - leadz(x)
  end function bit_size_of

end module text_scanner
