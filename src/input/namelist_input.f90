!> A namelist reader for input decks, with our own checking: Fortran namelist text is
!! split into groups `&name ... /` and assignments `name = value`, and each group is read
!! against a table of the variables it may set (`namelist_vars`). Names, subscripts, value
!! counts, types, enumeration spellings and string lengths are checked here, with messages
!! naming the source (deck file and line, or command-line override), group, variable and
!! value and echoing the line. gfortran's own namelist messages are poor, so no namelist
!! READ is used.
!!
!! A deck's groups are declared once (`deck_tables`), as one table per group: a setting
!! added to a group is one line in its table plus its field in `config`.
module namelist_input
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT
  use strings, only: fpstate_t, fp_read_begin, fp_read_end, lower, is_ident, is_letter, first_nonblank, &
                     i2s, quote, quoted_list, index_of, text_buffer_t
  use namelist_vars, only: str_t, vars_t, T_INT, T_REAL, T_STR, T_ENUM, var_index, var_list
  implicit none (type, external)
  private

  character(len=*), parameter :: NL = achar(10)


  !> A source of namelist text: the deck file or one command-line override.
  type, public :: src_t
    character(len=:), allocatable :: label      !< deck path, or 'command-line override k'
    logical :: is_file = .false.                !< a file (messages give line numbers)
    type(str_t), allocatable :: lines(:)        !< raw lines, for echoing
  end type src_t

  !> One `name = value` assignment inside a group.
  type, public :: asg_t
    character(len=:), allocatable :: name       !< lower case, without subscript
    character(len=:), allocatable :: value      !< value text as written (trimmed)
    integer :: sub = 0                          !< subscript, 0 if none
    integer :: line = 0                         !< line of the name
  end type asg_t

  !> One namelist group fragment `&name ... /`.
  type, public :: grp_t
    character(len=:), allocatable :: name       !< lower case
    character(len=:), allocatable :: text       !< the fragment on one record
    integer :: line = 0                         !< line of the '&'
    integer :: nasg = 0                         !< number of assignments
    type(asg_t), allocatable :: a(:)            !< the assignments, in order
  end type grp_t

  public :: load_file, text_source, parse_source, read_group
  public :: find_asg, find_int, die_at, bad_value, unknown_group, check_enum

contains

  ! ============================================================================================
  ! Reading text and splitting it into groups and assignments
  ! ============================================================================================

  !> Read a deck file (a regular file, or a stream such as a pipe or /dev/stdin) as lines.
  subroutine load_file(path, src, err)
    character(len=*), intent(in) :: path   !< file path
    type(src_t), intent(out) :: src        !< its lines
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    logical :: exists
    integer :: u, ios, n
    character(len=512) :: msg
    character(len=:), allocatable :: text

    inquire (file=path, exist=exists)
    if (.not. exists) then
      call err%set(ERR_INPUT, 'cannot open the deck file '''//path// &
        ''': no such file')
      return
    end if
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call err%set(ERR_INPUT, 'cannot open the deck file '''//path//''': '//trim(msg))
      return
    end if
    inquire (unit=u, size=n)
    if (n <= 0) then
      ! a stream (pipe) has no size (-1, or 0 for some): read it record by record
      close (u)
      call read_stream(path, text, err)
      if (err%failed()) return
    else
      allocate (character(len=n) :: text)
      if (n > 0) then
        read (u, iostat=ios, iomsg=msg) text
        if (ios /= 0) then
          call err%set(ERR_INPUT, 'cannot read the deck file '''//path//''': '//trim(msg))
          close (u)
          return
        end if
      end if
      close (u)
    end if
    src%label = path
    src%is_file = .true.
    call split_lines(text, src%lines)
  end subroutine load_file

  !> The whole text of a sequential file of unknown size (pipe), lines joined by LF.
  subroutine read_stream(path, text, err)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    character(len=4096) :: chunk
    type(text_buffer_t) :: tb
    integer :: u, ios, nread
    character(len=512) :: msg
    open (newunit=u, file=path, access='sequential', form='formatted', status='old', &
          action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) then
      call err%set(ERR_INPUT, 'cannot open the deck file '''//path//''': '//trim(msg))
      return
    end if
    do
      read (u, '(a)', advance='no', size=nread, iostat=ios, iomsg=msg) chunk
      if (is_iostat_end(ios)) exit
      if (ios /= 0 .and. .not. is_iostat_eor(ios)) then
        call err%set(ERR_INPUT, 'cannot read the deck file '''//path//''': '//trim(msg))
        close (u)
        return
      end if
      call tb%add(chunk(1:nread))
      if (is_iostat_eor(ios)) call tb%add(NL)
    end do
    close (u)
    text = tb%text()
  end subroutine read_stream

  subroutine text_source(text, label, src)
    character(len=*), intent(in) :: text, label
    type(src_t), intent(out) :: src
    src%label = label
    src%is_file = .false.
    call split_lines(text, src%lines)
  end subroutine text_source

  subroutine split_lines(text, lines)
    character(len=*), intent(in) :: text
    type(str_t), allocatable, intent(out) :: lines(:)
    integer :: n, i, p, q, k
    n = 1
    do i = 1, len(text)
      if (text(i:i) == NL) n = n + 1
    end do
    if (len(text) > 0) then
      if (text(len(text):len(text)) == NL) n = n - 1
    end if
    allocate (lines(n))
    p = 1
    do k = 1, n
      q = index(text(p:), NL)
      if (q == 0) then
        q = len(text) + 1
      else
        q = p + q - 1
      end if
      lines(k)%s = text(p:q - 1)
      if (len(lines(k)%s) > 0) then
        if (lines(k)%s(len(lines(k)%s):) == achar(13)) lines(k)%s = lines(k)%s(:len(lines(k)%s) - 1)
      end if
      p = q + 1
    end do
  end subroutine split_lines

  !> Strip comments, join the lines into one buffer (with the line of every character),
  !! split it into groups and each group into assignments.
  subroutine parse_source(src, groups, gs, err)
    type(src_t), intent(in) :: src                  !< the text
    character(len=*), intent(in) :: groups          !< the known group names (for messages)
    type(grp_t), allocatable, intent(out) :: gs(:)  !< its groups, in order
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(str_t), allocatable :: clean(:)
    character(len=:), allocatable :: buf, gname
    integer, allocatable :: lineof(:)
    integer :: i, n, p, q, r, ng, bad
    character :: quote_ch, ch
    type(grp_t), allocatable :: tmp(:)

    allocate (clean(size(src%lines)))
    n = 0
    do i = 1, size(src%lines)
      call strip_comment(src%lines(i)%s, clean(i)%s, bad)
      if (bad > 0) then
        call die_at(src, i, 'unterminated character string: the quote at column '// &
          i2s(bad)//' is not closed on this line', err)
        return
      end if
      n = n + len(clean(i)%s) + 1
    end do
    allocate (character(len=n) :: buf)
    allocate (lineof(n))
    p = 0
    do i = 1, size(clean)
      buf(p + 1:p + len(clean(i)%s) + 1) = clean(i)%s//' '
      lineof(p + 1:p + len(clean(i)%s) + 1) = i
      p = p + len(clean(i)%s) + 1
    end do

    allocate (gs(8))
    ng = 0
    p = 1
    do while (p <= n)
      ch = buf(p:p)
      if (ch == ' ') then
        p = p + 1
        cycle
      end if
      if (ch /= '&') then
        q = p
        do while (q < n)
          if (buf(q + 1:q + 1) == ' ') exit
          q = q + 1
        end do
        if (ng == 0) then
          call die_at(src, lineof(p), 'syntax error: unexpected text '''//buf(p:q)// &
            ''' outside a namelist group; a group looks like &name var=value, ... /', err)
          return
        else
          call die_at(src, lineof(p), 'syntax error: unexpected text '''//buf(p:q)// &
            ''' after the ''/'' that closes group &'//gs(ng)%name//' (line '// &
            i2s(gs(ng)%line)//'); a group looks like &name var=value, ... /', err)
          return
        end if
      end if
      q = p + 1
      do while (q <= n)
        if (.not. is_ident(buf(q:q))) exit
        q = q + 1
      end do
      gname = lower(buf(p + 1:q - 1))
      if (len(gname) == 0) then
        call die_at(src, lineof(p), 'syntax error: ''&'' must be followed '// &
          'by a group name (one of '//quoted_list(groups, '&')//')', err)
        return
      end if
      if (.not. is_letter(gname(1:1))) then
        call die_at(src, lineof(p), 'syntax error: ''&'// &
          gname//''' is not a group name', err)
        return
      end if
      ! Find the closing '/', outside quotes.
      r = q
      quote_ch = ' '
      do while (r <= n)
        ch = buf(r:r)
        if (quote_ch /= ' ') then
          if (ch == quote_ch) quote_ch = ' '
        else if (ch == '''' .or. ch == '"') then
          quote_ch = ch
        else if (ch == '/') then
          exit
        else if (ch == '&') then
          call die_at(src, lineof(r), 'syntax error: group &'//gname//' (line '// &
            i2s(lineof(p))//') is not closed with ''/'' before the next ''&'' on line '// &
            i2s(lineof(r)), err)
          return
        end if
        r = r + 1
      end do
      if (r > n) then
        call die_at(src, lineof(p), 'syntax error: group &'//gname// &
          ' is not closed: a group ends with ''/''', err)
        return
      end if
      if (ng == size(gs)) then   ! grow geometrically: many groups stay linear
        allocate (tmp(max(8, 2*ng)))
        tmp(1:ng) = gs(1:ng)
        call move_alloc(tmp, gs)
      end if
      ng = ng + 1
      gs(ng)%name = gname
      gs(ng)%text = buf(p:r)
      gs(ng)%line = lineof(p)
      call split_assignments(src, gs(ng), buf(q:r - 1), lineof(q:r - 1), err)
      if (err%failed()) return
      p = r + 1
    end do
    gs = gs(1:ng)
  end subroutine parse_source

  !> Remove a `!` comment (outside quotes) and turn tabs outside quotes into blanks.
  !! `bad` > 0 is the column of an unclosed quote.
  subroutine strip_comment(line, out, bad)
    character(len=*), intent(in) :: line
    character(len=:), allocatable, intent(out) :: out
    integer, intent(out) :: bad
    integer :: i, n
    character :: q
    q = ' '
    bad = 0
    out = line
    n = len(line)
    do i = 1, len(line)
      if (q /= ' ') then
        if (line(i:i) == q) q = ' '
      else if (line(i:i) == '''' .or. line(i:i) == '"') then
        q = line(i:i)
        bad = i
      else if (line(i:i) == '!') then
        n = i - 1
        exit
      else if (line(i:i) == achar(9)) then
        out(i:i) = ' '
      end if
    end do
    if (q == ' ') bad = 0
    out = out(1:n)
  end subroutine strip_comment

  !> Split the inside of a group (after its name, before '/') into assignments.
  subroutine split_assignments(src, g, body, lineof, err)
    type(src_t), intent(in) :: src
    type(grp_t), intent(inout) :: g
    character(len=*), intent(in) :: body
    integer, intent(in) :: lineof(:)
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer, allocatable :: eqs(:), nstart(:)
    integer :: i, j, k, e, ne, jp, ios
    character :: q
    character(len=:), allocatable :: v

    ! Positions of '=' outside quotes.
    allocate (eqs(0))
    q = ' '
    do i = 1, len(body)
      if (q /= ' ') then
        if (body(i:i) == q) q = ' '
      else if (body(i:i) == '''' .or. body(i:i) == '"') then
        q = body(i:i)
      else if (body(i:i) == '=') then
        eqs = [eqs, i]
      end if
    end do
    ne = size(eqs)
    if (ne == 0) then
      if (len_trim(body) > 0) then
        call die_at(src, lineof(first_nonblank(body)), &
          'syntax error in group &'//g%name//': expected name=value, found '''// &
          trim(adjustl(body))//'''', err)
        return
      end if
      g%nasg = 0
      allocate (g%a(0))
      return
    end if
    allocate (nstart(ne), g%a(ne))
    g%nasg = ne
    do k = 1, ne
      j = eqs(k) - 1
      do while (j >= 1)
        if (body(j:j) /= ' ') exit
        j = j - 1
      end do
      g%a(k)%sub = 0
      if (j >= 1) then
        if (body(j:j) == ')') then
          jp = index(body(1:j), '(', back=.true.)
          if (jp == 0) then
            call die_at(src, lineof(j), 'syntax error in group &'//g%name// &
              ': unbalanced '')'' before ''=''', err)
            return
          end if
          read (body(jp + 1:j - 1), *, iostat=ios) g%a(k)%sub
          if (ios /= 0 .or. g%a(k)%sub < 1 .or. verify(trim(adjustl(body(jp + 1:j - 1))), &
                                                           '0123456789') /= 0) then
            call die_at(src, lineof(j), 'in group &'//g%name//': bad subscript ('// &
              body(jp + 1:j - 1)//'); only a single index such as t0(2) is accepted', err)
            return
          end if
          j = jp - 1
          do while (j >= 1)
            if (body(j:j) /= ' ') exit
            j = j - 1
          end do
        end if
      end if
      e = j
      do while (j >= 1)
        if (.not. is_ident(body(j:j))) exit
        j = j - 1
      end do
      if (j + 1 > e) then
        call die_at(src, lineof(eqs(k)), 'syntax error in group &'//g%name// &
          ': misplaced ''='' (no variable name before it)', err)
        return
      end if
      if (.not. is_letter(body(j + 1:j + 1))) then
        call die_at(src, lineof(j + 1), &
          'syntax error in group &'//g%name//': '''//body(j + 1:e)//''' is not a variable name', err)
        return
      end if
      if (j >= 1) then
        if (body(j:j) /= ' ' .and. body(j:j) /= ',') then
          call die_at(src, lineof(j + 1), &
            'syntax error in group &'//g%name//': '''//body(j:e)//''' is not a variable name', err)
          return
        end if
      end if
      nstart(k) = j + 1
      g%a(k)%name = lower(body(j + 1:e))
      g%a(k)%line = lineof(j + 1)
    end do
    if (len_trim(body(1:nstart(1) - 1)) > 0) then
      call die_at(src, lineof(first_nonblank(body)), &
        'syntax error in group &'//g%name//': expected name=value, found '''// &
        trim(adjustl(body(1:nstart(1) - 1)))//'''', err)
      return
    end if
    do k = 1, ne
      if (k < ne) then
        v = trim(adjustl(body(eqs(k) + 1:nstart(k + 1) - 1)))
      else
        v = trim(adjustl(body(eqs(k) + 1:)))
      end if
      if (len(v) > 0) then
        if (v(len(v):len(v)) == ',') v = trim(v(1:len(v) - 1))
      end if
      g%a(k)%value = v
    end do
  end subroutine split_assignments

  ! ============================================================================================
  ! Reading a group into its variables
  ! ============================================================================================

  !> Read every assignment of `g` into its variable of `vars`, checking the name (known,
  !! given once), the subscript, the number and type of values, enumeration spellings and
  !! string lengths. Null values leave a variable unchanged; `n*value` repeats a value.
  subroutine read_group(g, src, vars, err)
    type(grp_t), intent(in) :: g        !< the group
    type(src_t), intent(in) :: src      !< where it comes from (for messages)
    type(vars_t), intent(inout) :: vars !< its variables, bound to their storage
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k, j, i, nitem, rep, ios, pos, m, code, kk
    type(str_t), allocatable :: items(:)
    character(len=:), allocatable :: tok, head, txt
    real(wp) :: x
    type(fpstate_t) :: fps

    do k = 1, g%nasg
      associate (a => g%a(k))
        j = var_index(vars, a%name)
        if (j == 0) then
          call die_at(src, a%line, 'in group &'//g%name//': unknown variable '''// &
            a%name//'''; the variables of &'//g%name//' are '//var_list(vars), err)
          return
        end if
        do kk = 1, k - 1
          if (g%a(kk)%name == a%name .and. (g%a(kk)%sub == a%sub .or. g%a(kk)%sub == 0 .or. a%sub == 0)) then
            call die_at(src, a%line, 'in group &'//g%name//': '//a%name//' is given twice in this '// &
              'group (also at line '//i2s(g%a(kk)%line)//'); give each variable once', err)
            return
          end if
        end do
        associate (v => vars%v(j))
          head = 'in group &'//g%name//': '//a%name//' = '//a%value
          if (a%sub > 0) then
            if (v%nval == 1) then
              call die_at(src, a%line, 'in group &'//g%name//': '//a%name// &
                ' is a single value and takes no subscript', err)
              return
            end if
            if (a%sub > v%nval) then
              call die_at(src, a%line, 'in group &'//g%name//': subscript '// &
                i2s(a%sub)//' of '//a%name//' is out of range (1 to '//i2s(v%nval)//')', err)
              return
            end if
          end if
          call split_items(a%value, items)
          ! count the values first: too many is an error whatever they are
          ! (a count above what the variable takes stops the sum before it can overflow)
          nitem = 0
          do i = 1, size(items)
            call repeat_count(items(i)%s, rep, tok)
            nitem = nitem + min(rep, v%nval + 1)
            if (nitem > v%nval) exit
          end do
          if (nitem > merge(1, v%nval, a%sub > 0)) then
            if (v%nval == 1 .or. a%sub > 0) then
              call die_at(src, a%line, head//': too many values ('//a%name//' takes one value)', err)
              return
            else if (v%typ == T_REAL) then
              call die_at(src, a%line, head//': too many values ('//a%name//' takes '// &
                i2s(v%nval)//': the '//trim(merge('x and y   ', 'x, y and z', v%nval == 2))//' components)', err)
              return
            else
              call die_at(src, a%line, head//': too many values ('//a%name//' takes '// &
                i2s(v%nval)//')', err)
              return
            end if
          end if
          pos = max(a%sub, 1)
          do i = 1, size(items)
            call repeat_count(items(i)%s, rep, tok)
            if (rep < 0) then
              call die_at(src, a%line, head//': bad repeat count in '''//items(i)%s//'''', err)
              return
            end if
            if (len(tok) == 0) then   ! null value: leaves the variable unchanged
              pos = pos + rep
              cycle
            end if
            select case (v%typ)
            case (T_INT)
              if (verify(tok, '+-0123456789') /= 0 .or. verify(tok(2:), '0123456789') /= 0 .or. &
                  verify(tok, '+-') == 0) then
                call die_at(src, a%line, head//': expected an integer, e.g. '//a%name//'=24, found '//tok, err)
                return
              end if
              read (tok, *, iostat=ios) m
              if (ios /= 0) then
                call die_at(src, a%line, head//': the integer '//tok//' is out of range', err)
                return
              end if
              if (v%nval == 1) then
                v%ip = m
              else
                v%iv(pos:pos + rep - 1) = m
              end if
            case (T_REAL)
              call fp_read_begin(fps)
              read (tok, *, iostat=ios) x
              call fp_read_end(fps)
              if (ios /= 0 .or. scan(tok, '''"/(),;') > 0 .or. verify(tok(1:1), '+-.0123456789') /= 0) then
                if (verify(lower(tok), '+-nafity') == 0 .and. ios == 0) then
                  call die_at(src, a%line, head//': '//tok//' is not a finite real number', err)
                  return
                end if
                call die_at(src, a%line, head//': expected a real number, e.g. '// &
                  a%name//'=1.5e6, found '//tok, err)
                return
              end if
              if (.not. ieee_is_finite(x)) then
                call die_at(src, a%line, head//': '//tok// &
                  ' is not a finite real number', err)
                return
              end if
              if (v%nval == 1) then
                v%rs = x
              else
                v%rv(pos:pos + rep - 1) = x
              end if
            case default   ! T_STR, T_ENUM
              if (.not. is_quoted(tok)) then
                call die_at(src, a%line, head// &
                  ': expected a quoted character string, e.g. '//a%name//'=''...'', found '//tok, err)
                return
              end if
              txt = unquote(tok)
              if (v%typ == T_STR .and. v%nval > 1) then
                if (len_trim(txt) > len(v%sv(pos)%p)) then
                  call die_at(src, a%line, head//': '''//txt// &
                    ''' is too long (at most '//i2s(len(v%sv(pos)%p))//' characters)', err)
                  return
                end if
                do m = pos, pos + rep - 1
                  v%sv(m)%p = txt
                end do
              else if (v%typ == T_STR) then
                if (len_trim(txt) > len(v%sp)) then
                  call die_at(src, a%line, head//': is too long (at most '// &
                    i2s(len(v%sp))//' characters)', err)
                  return
                end if
                v%sp = txt
              else
                call check_enum(g, src, a%name, txt, v%choices, code, err)
                if (err%failed()) return
                v%ip = v%base + code - 1
              end if
            end select
            pos = pos + rep
          end do
        end associate
      end associate
    end do
  end subroutine read_group

  !> Split `n*value` into its count and value (count 1 without a star; -1 if the count is bad).
  subroutine repeat_count(item, rep, tok)
    character(len=*), intent(in) :: item
    integer, intent(out) :: rep
    character(len=:), allocatable, intent(out) :: tok
    integer :: star, ios
    rep = 1
    tok = item
    star = scan(item, '*')
    if (star > 0 .and. item(1:1) /= '''' .and. item(1:1) /= '"') then
      read (item(1:star - 1), *, iostat=ios) rep
      if (ios /= 0 .or. rep < 1 .or. verify(item(1:star - 1), '0123456789') /= 0) rep = -1
      tok = item(star + 1:)
    end if
  end subroutine repeat_count

  !> The text of a quoted string literal: outer quotes removed, doubled quotes single.
  function unquote(tok) result(s)
    character(len=*), intent(in) :: tok
    character(len=:), allocatable :: s
    character :: q
    integer :: i
    q = tok(1:1)
    s = ''
    i = 2
    do while (i <= len(tok) - 1)
      s = s//tok(i:i)
      if (tok(i:i) == q) i = i + 1
      i = i + 1
    end do
  end function unquote

  !> Split a namelist value into items (blank/comma separated, quote aware); null items
  !! (between two commas) are empty strings.
  subroutine split_items(v, items)
    character(len=*), intent(in) :: v
    type(str_t), allocatable, intent(out) :: items(:)
    integer :: i, start
    logical :: intok, comma_pending
    character :: q, ch
    allocate (items(0))
    intok = .false.
    comma_pending = .true.   ! a comma at the very start means a null first item
    q = ' '
    start = 1
    do i = 1, len(v)
      ch = v(i:i)
      if (intok) then
        if (q /= ' ') then
          if (ch == q) q = ' '
          cycle
        end if
        if (ch == ' ' .or. ch == ',') then
          items = [items, str_t(v(start:i - 1))]
          intok = .false.
          comma_pending = (ch == ',')
        else if (ch == '''' .or. ch == '"') then
          q = ch
        end if
      else
        if (ch == ' ') cycle
        if (ch == ',') then
          if (comma_pending) items = [items, str_t('')]
          comma_pending = .true.
          cycle
        end if
        intok = .true.
        start = i
        comma_pending = .false.
        if (ch == '''' .or. ch == '"') q = ch
      end if
    end do
    if (intok) items = [items, str_t(v(start:))]
  end subroutine split_items

  logical function is_quoted(tok)
    character(len=*), intent(in) :: tok
    integer :: i
    character :: q
    is_quoted = .false.
    if (len(tok) < 2) return
    q = tok(1:1)
    if (q /= '''' .and. q /= '"') return
    if (tok(len(tok):len(tok)) /= q) return
    i = 2
    do while (i <= len(tok) - 1)
      if (tok(i:i) == q) then
        if (tok(i + 1:i + 1) /= q .or. i + 1 > len(tok) - 1) return
        i = i + 2
      else
        i = i + 1
      end if
    end do
    is_quoted = .true.
  end function is_quoted

  !> Index of the last assignment to `name` in g, 0 if none.
  integer function find_asg(g, name)
    type(grp_t), intent(in) :: g
    character(len=*), intent(in) :: name
    integer :: k
    find_asg = 0
    do k = g%nasg, 1, -1
      if (g%a(k)%name == name) then
        find_asg = k
        return
      end if
    end do
  end function find_asg

  !> Value of an integer assignment (already checked by check_group); `found` false if
  !! absent or null.
  subroutine find_int(g, name, val, found)
    type(grp_t), intent(in) :: g
    character(len=*), intent(in) :: name
    integer, intent(out) :: val
    logical, intent(out) :: found
    integer :: k, ios
    val = 0
    found = .false.
    k = find_asg(g, name)
    if (k == 0) return
    if (len_trim(g%a(k)%value) == 0) return
    read (g%a(k)%value, *, iostat=ios) val
    found = (ios == 0)
  end subroutine find_int

  ! ============================================================================================
  ! Errors
  ! ============================================================================================

  !> Bad input at a line of a source, with the line echoed: `err` holds ERR_INPUT and the
  !! message, which starts with the source's label (and the line, in a file).
  subroutine die_at(src, line, msg, err)
    type(src_t), intent(in) :: src
    integer, intent(in) :: line
    character(len=*), intent(in) :: msg
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    character(len=:), allocatable :: m
    character(len=6) :: num
    integer :: i
    if (src%is_file) then
      if (line >= 1 .and. line <= size(src%lines)) then
        write (num, '(i6)') line
        m = src%label//':'//i2s(line)//': '//msg//NL//num//' | '//src%lines(line)%s
      else
        m = src%label//': '//msg
      end if
    else
      m = src%label//': '//msg//NL//'       | '
      do i = 1, size(src%lines)
        m = m//src%lines(i)%s//' '
      end do
    end if
    call err%set(ERR_INPUT, m)
  end subroutine die_at

  !> Bad input: the value of one variable of a group (at the line where it is set).
  subroutine bad_value(g, src, name, shown, why, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: name   ! variable
    character(len=*), intent(in) :: shown  ! its value, used when it is not set in this group
    character(len=*), intent(in) :: why
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k
    k = find_asg(g, name)
    if (k > 0) then
      call die_at(src, g%a(k)%line, 'in group &'//g%name//': '//name//' = '//g%a(k)%value// &
        ' '//why, err)
    else
      call die_at(src, g%line, 'in group &'//g%name//': '//name//' = '//shown// &
        ' (not set in this group) '//why, err)
    end if
  end subroutine bad_value

  !> An enumeration: `value` must be one of the blank-separated `allowed` (any case);
  !! `k` is its position in the list.
  subroutine check_enum(g, src, name, value, allowed, k, err)
    type(grp_t), intent(in) :: g                         !< the group
    type(src_t), intent(in) :: src                       !< where it comes from
    character(len=*), intent(in) :: name, value, allowed !< variable, its value, the choices
    integer, intent(out) :: k                            !< position of the value in `allowed`
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    k = index_of(allowed, trim(adjustl(value)))
    if (k == 0) then
      call bad_value(g, src, name, quote(trim(value)), 'is not allowed; the allowed '// &
        'values are '//quoted_list(allowed, ''), err)
    end if
  end subroutine check_enum

  !> Bad input: a group that is not one of `groups` (blank-separated).
  subroutine unknown_group(g, src, groups, err)
    type(grp_t), intent(in) :: g                !< the group
    type(src_t), intent(in) :: src              !< where it comes from
    character(len=*), intent(in) :: groups      !< the known group names
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    call die_at(src, g%line, 'unknown group &'//g%name//'; the groups are '// &
      quoted_list(groups, '&'), err)
  end subroutine unknown_group

end module namelist_input
