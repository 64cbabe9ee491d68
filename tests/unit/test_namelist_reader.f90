!> Unit tests of the namelist reader (modules namelist_input and namelist_vars) on a made-up
!! group `&part` whose table holds one variable of every kind (integer, real, a pair and a
!! vector of reals, an integer pair, an integer list, a string, a string pair, a choice),
!! read from texts written here, against the values the texts spell (for a real, the
!! compiler's own reading of the same literal in this source, bit for bit):
!!  - comments (after values, on lines of their own, a `!` inside quotes kept), a group over
!!    several lines, tabs and CRLF line ends, upper case names, several assignments on a line
!!    with and without commas, two groups of the same name read in order (each from its own
!!    line), a group with no assignment;
!!  - reals in the forms Fortran reads: 1, 1., .5, -.5, +2.5, 1e3, 1E+3, 1.5d-3, 1.5D+3,
!!    2.5e+02, 6.02214076E23, -0.0 (its sign), 1.0+3 (an exponent without its letter);
!!  - arrays: a pair and a vector in full, repeat counts (2*0.5, 3*7), a subscript (v(2) =)
!!    leaving the other component, a null value (`, 4.0`) leaving it too, an integer list
!!    shorter than its storage (the rest `unset`), blank-separated values;
!!  - strings: doubled quotes inside quotes of either kind, the other quote kind inside,
!!    `!`, `/`, `=`, `&` and `,` inside quotes, a string pair, a choice in any case;
!!  - find_asg and find_int;
!!  - malformed input: 27 texts, each read from a file in this process as a deck reads its
!!    groups: ERR_INPUT (exit code 1) and the message starting with the file's path, naming
!!    the line, the group and the variable (an unknown variable, a
!!    real for an integer, a string for a real, a real with a kind suffix, NaN, 1e999, too
!!    many values, a variable given twice, subscripts out of range, on a scalar and not an
!!    integer, a choice not allowed, a string too long, unquoted, unterminated, a group not
!!    closed, closed by the next group, text outside a group and after one, a bad repeat
!!    count, an integer out of range, a misplaced `=`, a name starting with a digit, a value
!!    without a name, an unknown group, a string in an integer list), with the line echoed.
!! The files are written under build/<kind>/test-namelist (beside the folder of this
!! program), so that a release and a checked build's tests running at once do not share them.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_namelist_reader
  use, intrinsic :: iso_fortran_env, only: int64
  use kinds, only: wp
  use namelist_vars, only: vars_t
  use namelist_input, only: src_t, grp_t, text_source, load_file, parse_source, read_group, find_asg, find_int, &
                            unknown_group
  use errors, only: error_t, exit_code, ERR_INPUT, EXIT_INPUT
  use strings, only: i2s
  use testing, only: report, test_summary, scratch_path, fresh_folder
  implicit none (type, external)

  character(len=*), parameter :: NL = achar(10)
  character(len=:), allocatable :: dir   ! build/<kind>/test-namelist
  character(len=*), parameter :: GROUPS = 'part other'
  integer, parameter :: NBAD = 27

  ! the storage the table of &part is bound to
  integer, target :: n, ids(2), list(5), kind_code
  real(wp), target :: x, v(2), w(3)
  character(len=16), target :: name
  character(len=8), target :: names(2)
  type(vars_t) :: t

  call part_table(t)
  ! beside the folder of this program (build/<kind>/tests/)
  dir = scratch_path('test-namelist')
  call fresh_folder(dir)

  call test_layout()
  call test_reals()
  call test_arrays()
  call test_strings()
  call test_bad()
  call test_summary()

contains

  !> The table of &part, bound to the storage above.
  subroutine part_table(tab)
    type(vars_t), intent(out) :: tab
    call tab%int('n', n)
    call tab%real('x', x)
    call tab%pair('v', v)
    call tab%pair('w', w)
    call tab%ints('ids', ids)
    call tab%list('list', list, unset=-1)
    call tab%str('name', name)
    call tab%strs('names', names)
    call tab%enum('kind', kind_code, 'alpha beta gamma', base=0)
  end subroutine part_table

  !> The defaults of &part's storage.
  subroutine defaults()
    n = -1
    ids = [-1, -1]
    list = -1
    kind_code = -1
    x = -1.0_wp
    v = [-1.0_wp, -1.0_wp]
    w = [-1.0_wp, -1.0_wp, -1.0_wp]
    name = 'none'
    names = ['none', 'none']
  end subroutine defaults

  !> Defaults, then the one group of `text` read into the storage.
  subroutine read_one(text)
    character(len=*), intent(in) :: text
    type(grp_t), allocatable :: gs(:)
    type(src_t) :: src
    type(error_t) :: err
    call defaults()
    call text_source(text, 'test text', src)
    call parse_source(src, GROUPS, gs, err)
    if (err%failed()) error stop 'read_one: '//err%message
    if (size(gs) /= 1) error stop 'read_one: not one group'
    call read_group(gs(1), src, t, err)
    if (err%failed()) error stop 'read_one: '//err%message
  end subroutine read_one

  !> The 64-bit patterns of two reals are equal.
  elemental logical function same(a, b)
    real(wp), intent(in) :: a, b
    same = transfer(a, 0_int64) == transfer(b, 0_int64)
  end function same

  ! ---- layout: comments, lines, groups ---------------------------------------------------------

  subroutine test_layout()
    type(grp_t), allocatable :: gs(:)
    type(src_t) :: src
    character(len=:), allocatable :: text
    integer :: val
    logical :: found
    type(error_t) :: err
    text = '! a deck of two parts'//NL// &
           '&part n = 3,          ! a comment after a value'//NL// &
           achar(9)//'x = 1.5e3'//achar(9)//'! the group goes on, a tab before it'//NL// &
           '   ! a comment line inside the group'//NL// &
           '      name = ''tab'//achar(9)//'kept!'' /'//achar(13)//NL// &
           '&PART N=-7 X=.5, IDS=1 2/ &other /'//NL// &
           '&part'//NL// &
           '/'
    call text_source(text, 'test text', src)
    call parse_source(src, GROUPS, gs, err)
    call report(.not. err%failed() .and. size(gs) == 4, 'layout: four groups (two on one line, one over two lines)')
    if (size(gs) /= 4) return
    call report(gs(1)%name == 'part' .and. gs(2)%name == 'part' .and. gs(3)%name == 'other' .and. &
                gs(4)%name == 'part' .and. all([gs%line] == [2, 6, 6, 7]), &
                'layout: the groups in order, names in lower case, each at the line of its &')
    call report(gs(1)%nasg == 3 .and. gs(2)%nasg == 3 .and. gs(3)%nasg == 0 .and. gs(4)%nasg == 0, &
                'layout: three assignments in each &part with values, none in the others')
    call report(all([gs(1)%a%line] == [2, 3, 5]) .and. gs(2)%a(3)%name == 'ids' .and. gs(2)%a(3)%value == '1 2', &
                'layout: each assignment at the line of its name (comment lines skipped), its value as written')
    call defaults()
    call read_group(gs(1), src, t, err)
    call report(.not. err%failed() .and. n == 3 .and. same(x, 1.5e3_wp) .and. name == 'tab'//achar(9)//'kept!', &
                'layout: comments and the line ends (CR) dropped, a tab and a ! inside quotes kept')
    call read_group(gs(2), src, t, err)
    call report(.not. err%failed() .and. n == -7 .and. same(x, 0.5_wp) .and. all(ids == [1, 2]) .and. name == 'tab'//achar(9)//'kept!', &
                'layout: a second &part (upper case, with and without commas) sets only what it gives')
    call read_group(gs(4), src, t, err)
    call report(.not. err%failed() .and. n == -7, 'layout: an empty group changes nothing')
    call find_int(gs(2), 'n', val, found)
    call report(find_asg(gs(1), 'x') == 2 .and. find_asg(gs(1), 'v') == 0 .and. found .and. val == -7, &
                'find_asg, find_int: the assignment of a name, an integer''s value')
  end subroutine test_layout

  ! ---- reals --------------------------------------------------------------------------------

  subroutine test_reals()
    character(len=16), parameter :: forms(13) = [character(len=16) :: '1', '1.', '.5', '-.5', '+2.5', '1e3', '1E+3', &
                                                  '1.5d-3', '1.5D+3', '2.5e+02', '6.02214076E23', '-0.0', '1.0+3']
    real(wp), parameter :: values(13) = [1.0_wp, 1.0_wp, 0.5_wp, -0.5_wp, 2.5_wp, 1.0e3_wp, 1.0e3_wp, 1.5e-3_wp, &
                                         1.5e3_wp, 2.5e2_wp, 6.02214076e23_wp, -0.0_wp, 1.0e3_wp]
    logical :: ok(13)
    integer :: i
    do i = 1, size(forms)
      call read_one('&part x = '//trim(forms(i))//' /')
      ok(i) = same(x, values(i))
      if (.not. ok(i)) write (*, '(a,es25.17)') '      '//trim(forms(i))//' read as ', x
    end do
    call report(all(ok(1:5)), 'reals: 1, 1., .5, -.5, +2.5 (bit for bit the compiler''s literals)')
    call report(all(ok(6:11)), 'reals: exponents 1e3, 1E+3, 1.5d-3, 1.5D+3, 2.5e+02, 6.02214076E23')
    call report(ok(12), 'reals: -0.0 keeps its sign')
    call report(ok(13), 'reals: 1.0+3 (an exponent without its letter) is 1000')
    call read_one('&part x = 3 /')
    call report(same(x, 3.0_wp), 'reals: an integer literal for a real')
  end subroutine test_reals

  ! ---- arrays ---------------------------------------------------------------------------------

  subroutine test_arrays()
    call read_one('&part v = 1.0, 2.0, w = 1 2 3, ids = 4, 5 /')
    call report(all(same(v, [1.0_wp, 2.0_wp])) .and. all(same(w, [1.0_wp, 2.0_wp, 3.0_wp])) .and. all(ids == [4, 5]), &
                'arrays: a pair, a vector (blank-separated), an integer pair')
    call read_one('&part v = 2*0.5, list = 3*7 /')
    call report(all(same(v, [0.5_wp, 0.5_wp])) .and. all(list == [7, 7, 7, -1, -1]), &
                'arrays: repeat counts 2*0.5 and 3*7 (the list''s other entries unset)')
    call read_one('&part v(2) = 3.0, w(3) = 9 /')
    call report(all(same(v, [-1.0_wp, 3.0_wp])) .and. all(same(w, [-1.0_wp, -1.0_wp, 9.0_wp])), &
                'arrays: a subscript sets its component alone')
    call read_one('&part v = , 4.0, ids = 8 /')
    call report(all(same(v, [-1.0_wp, 4.0_wp])) .and. all(ids == [8, -1]), &
                'arrays: a null value and a short list leave the other components')
    call read_one('&part list = 1, 2, 3, 4, 5 /')
    call report(all(list == [1, 2, 3, 4, 5]), 'arrays: an integer list filled')
    call read_one('&part w = 1*, 2*6.5 /')
    call report(all(same(w, [-1.0_wp, 6.5_wp, 6.5_wp])), 'arrays: a repeated null value (1*) leaves its component')
  end subroutine test_arrays

  ! ---- strings ---------------------------------------------------------------------------------

  subroutine test_strings()
    call read_one('&part name = ''it''''s'' /')
    call report(name == 'it''s', 'strings: a doubled apostrophe inside apostrophes ('//trim(name)//')')
    call read_one('&part name = "say ""hi""" /')
    call report(name == 'say "hi"', 'strings: a doubled quote inside quotes ('//trim(name)//')')
    call read_one('&part name = ''a "b" c'', names = "d''e", ''f"g'' /')
    call report(name == 'a "b" c' .and. names(1) == 'd''e' .and. names(2) == 'f"g', &
                'strings: the other kind of quote inside, a string pair')
    call read_one('&part name = ''!x/y=z&w,v'' /')
    call report(name == '!x/y=z&w,v', 'strings: ! / = & and , inside quotes are text ('//trim(name)//')')
    call read_one('&part name = '''' /')
    call report(name == '', 'strings: an empty string')
    call read_one('&part kind = ''GAMMA'' /')
    call report(kind_code == 2, 'choices: any case, stored as its code from the base (0, 1, 2)')
  end subroutine test_strings

  ! ---- malformed input -----------------------------------------------------------------------

  !> Malformed text k and the pieces its message must hold (separated by `|`).
  subroutine bad_case(k, text, expect)
    integer, intent(in) :: k
    character(len=:), allocatable, intent(out) :: text, expect
    select case (k)
    case (1)
      text = '&part n = 1,'//NL//'      nn = 2 /'
      expect = ':2: in group &part: unknown variable ''nn''|the variables of &part are n, x, v, w, ids, list, name, '// &
               'names, kind|     2 |       nn = 2 /'
    case (2)
      text = '&part n = 1.5 /'
      expect = ':1: in group &part: n = 1.5: expected an integer, e.g. n=24, found 1.5'
    case (3)
      text = '&part x = ''abc'' /'
      expect = ':1: in group &part: x = ''abc'': expected a real number, e.g. x=1.5e6, found ''abc'''
    case (4)
      text = '&part x = 1.5d0_8 /'
      expect = 'in group &part: x = 1.5d0_8: expected a real number'
    case (5)
      text = '&part x = NaN /'
      expect = 'in group &part: x = NaN: NaN is not a finite real number'
    case (6)
      text = '&part x = 1e999 /'
      expect = 'in group &part: x = 1e999: 1e999 is not a finite real number'
    case (7)
      text = '&part v = 1, 2, 3 /'
      expect = 'in group &part: v = 1, 2, 3: too many values (v takes 2: the x and y components)'
    case (8)
      text = '&part n = 1 2 /'
      expect = 'in group &part: n = 1 2: too many values (n takes one value)'
    case (9)
      text = '&part n = 1'//NL//'  x = 2, n = 3 /'
      expect = ':2: in group &part: n is given twice in this group (also at line 1)'
    case (10)
      text = '&part v(3) = 1.0 /'
      expect = 'in group &part: subscript 3 of v is out of range (1 to 2)'
    case (11)
      text = '&part n(1) = 2 /'
      expect = 'in group &part: n is a single value and takes no subscript'
    case (12)
      text = '&part v(1:2) = 1.0 /'
      expect = 'in group &part: bad subscript (1:2)'
    case (13)
      text = '&part kind = ''delta'' /'
      expect = 'in group &part: kind = ''delta'' is not allowed; the allowed values are ''alpha'', ''beta'' or ''gamma'''
    case (14)
      text = '&part name = ''12345678901234567'' /'
      expect = 'in group &part: name = ''12345678901234567'': is too long (at most 16 characters)'
    case (15)
      text = '&part name = abc /'
      expect = 'in group &part: name = abc: expected a quoted character string'
    case (16)
      text = '&part n = 2,'//NL//'  name = ''abc /'
      expect = ':2: unterminated character string: the quote at column 10 is not closed on this line'
    case (17)
      text = '&part n = 1'//NL//'  x = 2'
      expect = ':1: syntax error: group &part is not closed: a group ends with ''/'''
    case (18)
      text = '&part n = 1'//NL//'&other /'
      expect = ':2: syntax error: group &part (line 1) is not closed with ''/'' before the next ''&'' on line 2'
    case (19)
      text = 'n = 1'//NL//'&part /'
      expect = ':1: syntax error: unexpected text ''n'' outside a namelist group'
    case (20)
      text = '&part n = 1 /'//NL//'x = 2'
      expect = ':2: syntax error: unexpected text ''x'' after the ''/'' that closes group &part (line 1)'
    case (21)
      text = '&part v = 0*1.0 /'
      expect = 'in group &part: v = 0*1.0: bad repeat count in ''0*1.0'''
    case (22)
      text = '&part n = 99999999999 /'
      expect = 'in group &part: n = 99999999999: the integer 99999999999 is out of range'
    case (23)
      text = '&part = 1 /'
      expect = 'syntax error in group &part: misplaced ''='' (no variable name before it)'
    case (24)
      text = '&part 1x = 2 /'
      expect = 'syntax error in group &part: ''1x'' is not a variable name'
    case (25)
      text = '&part 42 /'
      expect = 'syntax error in group &part: expected name=value, found ''42'''
    case (26)
      text = '&part n = 1 /'//NL//'&foo n = 1 /'
      expect = ':2: unknown group &foo; the groups are &part or &other'
    case default
      text = '&part list = 1, ''a'' /'
      expect = 'in group &part: list = 1, ''a'': expected an integer, e.g. list=24, found ''a'''
    end select
  end subroutine bad_case

  !> Read malformed text k from its file as a deck reads its groups (unknown groups
  !! refused); `err` holds the refusal.
  subroutine read_bad(k, err)
    integer, intent(in) :: k
    type(error_t), intent(out) :: err
    type(src_t) :: src
    type(grp_t), allocatable :: gs(:)
    integer :: i
    call load_file(bad_path(k), src, err)
    if (err%failed()) return
    call parse_source(src, GROUPS, gs, err)
    if (err%failed()) return
    do i = 1, size(gs)
      if (gs(i)%name /= 'part' .and. gs(i)%name /= 'other') then
        call unknown_group(gs(i), src, GROUPS, err)
        return
      end if
      if (gs(i)%name == 'part') call read_group(gs(i), src, t, err)
      if (err%failed()) return
    end do
  end subroutine read_bad

  function bad_path(k) result(p)
    integer, intent(in) :: k
    character(len=:), allocatable :: p
    character(len=8) :: b
    write (b, '(i0)') k
    p = dir//'/bad_'//trim(b)//'.nml'
  end function bad_path

  subroutine test_bad()
    character(len=:), allocatable :: text, expect, msg, piece
    integer :: k, p
    logical :: ok
    type(error_t) :: err
    do k = 1, NBAD
      call bad_case(k, text, expect)
      call put_text(bad_path(k), text)
      call read_bad(k, err)
      msg = err%text()
      ok = err%category == ERR_INPUT .and. exit_code(err) == EXIT_INPUT .and. index(msg, bad_path(k)) == 1
      ! every piece of the expected text in the message
      do while (len(expect) > 0)
        p = index(expect, '|')
        if (p == 0) p = len(expect) + 1
        piece = expect(1:p - 1)
        if (piece(1:1) == ':') piece = bad_path(k)//piece
        ok = ok .and. index(msg, piece) > 0
        expect = expect(min(p + 1, len(expect) + 1):)
      end do
      if (index(msg, NL) > 0) msg = msg(1:index(msg, NL) - 1)
      call report(ok, 'malformed '//i2s(k)//': ERR_INPUT, '//trim(msg(min(len(msg), len(bad_path(k)) + 1):)))
    end do
  end subroutine test_bad

  subroutine put_text(path, text)
    character(len=*), intent(in) :: path, text
    integer :: u
    open (newunit=u, file=path, access='stream', form='unformatted', status='replace', action='write')
    write (u) text//NL
    close (u)
  end subroutine put_text



end program test_namelist_reader
