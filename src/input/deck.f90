!> The input deck: Fortran namelists read into a `deck_t`, validated value by value and
!! across fields, with clear messages on bad input, and rendered back as namelist text.
!!
!! Groups: `&scene`, `&body` (exactly two, ids 1 and 2), `&traction` and `&displacement`
!! (any number, any order), `&contact`, `&solver`, `&output` (each at most once; all
!! optional). Command-line overrides are namelist fragments applied after the deck:
!! `&body id=2, young=1e9 /` changes body 2, `&traction ... /` adds a traction, other
!! groups change the values given. Every bad input ends in `fatal(EXIT_INPUT, msg)` with
!! a message naming the source (deck file and line, or command-line override k), the
!! group, the variable and the value, followed by the offending line.
!!
!! Technique: read the whole file, strip `!` comments (outside quotes), split into group
!! fragments `&name ... /`, split each fragment into `name = value` assignments and check
!! names, subscripts, value counts and value types ourselves (gfortran's own messages are
!! poor), then read the fragment with a namelist READ from an internal unit into local
!! variables initialised from the current values, then check ranges and enumerations.
module deck
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use errors, only: fatal, warn, EXIT_INPUT
  use strings, only: fpstate_t, fp_read_begin, fp_read_end, lower, is_ident, is_letter, first_nonblank, &
                     i2s, r2s, quote, quoted_list, next_word, index_of, word
  use config, only: deck_t, body_cfg_t, traction_cfg_t, solver_cfg_t, output_cfg_t, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, side_names, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_CONTACT, BC_DISPLACEMENT, bc_names, &
                    ELEM_Q1, ELEM_P1, element_names
  implicit none
  private

  public :: read_deck, deck_text, print_deck, deck_usage

  character(len=*), parameter :: NL = achar(10)

  !> Usage text for the main program (printed when it is called without a deck).
  character(len=*), parameter :: deck_usage = &
    'usage: robin_contact DECK.nml [OVERRIDE ...]'//NL// &
    '  DECK.nml  input deck of Fortran namelist groups: &scene, two &body (id=1, id=2),'//NL// &
    '            any number of &traction and &displacement, &contact, &solver, &output'//NL// &
    '            (see inputs/default.nml, which documents every variable)'//NL// &
    '  OVERRIDE  a namelist fragment applied after the deck, in order, e.g.'//NL// &
    "              '&solver delta=0.5 /'   '&body id=2, young=1e9 /'"//NL// &
    '              "&traction body=1, side=''top'', t0=0.0,-1.0e6 /"   (adds a traction)'//NL// &
    '  Exit codes: 0 converged, 1 bad input or usage, 2 not converged, 3 numerical failure,'//NL// &
    '              4 interrupted (after a checkpoint).'

  ! Variable tables: name:type, type i (integer), r (real), s (quoted string),
  ! r2 (two reals, the x and y components).
  character(len=*), parameter :: V_SCENE = 'title:s plane:s'
  character(len=*), parameter :: V_BODY = 'id:i x0:r y0:r width:r height:r nx:i ny:i element:s &
    &young:r poisson:r left:s right:s top:s bottom:s'
  character(len=*), parameter :: V_TRACTION = 'body:i side:s t0:r2 t1:r2'
  character(len=*), parameter :: V_DISPLACEMENT = 'body:i side:s u:r2'
  character(len=*), parameter :: V_CONTACT = 'gap_radius:r gap_center:r'
  character(len=*), parameter :: V_SOLVER = 'method:s robin_operator:s alpha:r delta:r tol:r &
    &stop:s max_outer:i factorization:s ordering:s acceleration:s inner_factor:r &
    &inner_rtol_min:r inner_rtol_max:r inner_max_it:i monolithic_rtol:r'
  character(len=*), parameter :: V_OUTPUT = 'file:s checkpoint_every:i progress_lines:i'
  character(len=*), parameter :: GROUP_NAMES = 'scene body traction displacement contact solver output'

  ! Allowed values of the enumerations (canonical spelling; input is case-insensitive).
  character(len=*), parameter :: E_PLANE = 'strain stress'
  character(len=*), parameter :: E_ELEMENT = 'Q1 P1'
  character(len=*), parameter :: E_COND = 'free clamped roller contact displacement'
  character(len=*), parameter :: E_SIDE = 'left right bottom top'
  character(len=*), parameter :: E_METHOD = 'robin monolithic'
  character(len=*), parameter :: E_OPERATOR = 'steklov constant harmonic'
  character(len=*), parameter :: E_STOP = 'increment residual'
  character(len=*), parameter :: E_FACT = 'cholmod banded'
  character(len=*), parameter :: E_ORDERING = 'metis amd natural nd'
  character(len=*), parameter :: E_ACCEL = 'none aitken anderson'

  integer, parameter :: T_INT = 1, T_REAL = 2, T_STR = 3
  integer, parameter :: LSTR = 64     ! length of enumeration locals
  integer, parameter :: LLONG = 2048  ! length of title and file locals

  !> A variable-length string (for arrays of them).
  type :: str_t
    character(len=:), allocatable :: s
  end type str_t

  !> A source of namelist text: the deck file or one command-line override.
  type :: src_t
    character(len=:), allocatable :: label      ! deck path, or 'command-line override k'
    logical :: is_file = .false.
    type(str_t), allocatable :: lines(:)        ! raw lines, for echoing
  end type src_t

  !> One `name = value` assignment inside a group.
  type :: asg_t
    character(len=:), allocatable :: name       ! lower case, without subscript
    character(len=:), allocatable :: value      ! value text as written (trimmed)
    integer :: sub = 0                          ! subscript, 0 if none
    integer :: line = 0                         ! line of the name
  end type asg_t

  !> One namelist group fragment `&name ... /`.
  type :: grp_t
    character(len=:), allocatable :: name       ! lower case
    character(len=:), allocatable :: text       ! the fragment on one record
    integer :: line = 0                         ! line of the '&'
    integer :: nasg = 0
    type(asg_t), allocatable :: a(:)
  end type grp_t

  !> Where things came from, for cross-field messages.
  type :: state_t
    character(len=:), allocatable :: path
    integer :: nbody = 0
    integer :: body_line(2) = 0                 ! line of each &body in the deck file
    type(str_t) :: body_at(2)                   ! 'line N' or 'command-line override k'
    type(str_t), allocatable :: trac_at(:)      ! per traction
    integer :: disp_line(4, 2) = 0              ! deck line of the &displacement per side, body
    integer :: once_line(7) = 0                 ! deck line of each singleton group
  end type state_t

contains

  ! ============================================================================================
  ! Public API
  ! ============================================================================================

  !> Read the deck file `path`, then apply the command-line `overrides` in order, validate
  !! everything and fill `d` (with `d%effective`, the effective deck as namelist text).
  !! On any bad input: `fatal(EXIT_INPUT, message)`.
  subroutine read_deck(path, overrides, d)
    character(len=*), intent(in) :: path          !< deck file path
    character(len=*), intent(in) :: overrides(:)  !< namelist fragments from the command line
    type(deck_t), intent(out) :: d                !< the effective deck
    type(state_t) :: st
    type(src_t) :: src
    type(grp_t), allocatable :: gs(:)
    integer :: i, k, ig
    character(len=:), allocatable :: olabel

    d%source = path
    st%path = path
    allocate (d%traction(0), st%trac_at(0))
    d%ntraction = 0
    do k = 1, 2
      d%body(k)%id = 0
    end do

    call load_file(path, src)
    call parse_source(src, gs)

    ! Pass 1: everything but the loads, which refer to the bodies.
    do i = 1, size(gs)
      ig = index_of(GROUP_NAMES, gs(i)%name)
      if (ig == 0) call unknown_group(gs(i), src)
      select case (gs(i)%name)
      case ('traction', 'displacement')
        cycle
      case ('body')
        call new_body(gs(i), src, d, st)
      case default
        if (st%once_line(ig) > 0) call die_at(src, gs(i)%line, 'group &'//gs(i)%name// &
          ' appears twice in the deck (first at line '//i2s(st%once_line(ig))// &
          '); give each of its variables in one group')
        st%once_line(ig) = gs(i)%line
        call apply_single(gs(i), src, d)
      end select
    end do
    if (st%nbody == 0) call fatal(EXIT_INPUT, path//': the deck has no &body group; it needs '// &
      'exactly two, &body id=1 ... / and &body id=2 ... /')
    if (st%nbody == 1) then
      k = merge(1, 2, d%body(1)%id == 1)
      call fatal(EXIT_INPUT, path//': the deck has only one &body group (id='//i2s(k)// &
        ', line '//i2s(st%body_line(k))//'); it needs exactly two, with ids 1 and 2')
    end if

    ! Pass 2: loads, in deck order.
    do i = 1, size(gs)
      if (gs(i)%name == 'traction') call add_traction(gs(i), src, d, st, 'line '//i2s(gs(i)%line))
      if (gs(i)%name == 'displacement') call apply_displacement(gs(i), src, d, st)
    end do

    ! Command-line overrides, in order.
    do k = 1, size(overrides)
      olabel = 'command-line override '//i2s(k)
      call text_source(overrides(k), olabel, src)
      call parse_source(src, gs)
      if (size(gs) == 0) call fatal(EXIT_INPUT, olabel//': no namelist group in "'// &
        trim(overrides(k))//'"; an override looks like ''&solver delta=0.5 /''')
      do i = 1, size(gs)
        ig = index_of(GROUP_NAMES, gs(i)%name)
        if (ig == 0) call unknown_group(gs(i), src)
        select case (gs(i)%name)
        case ('body')
          call override_body(gs(i), src, d, st)
        case ('traction')
          call add_traction(gs(i), src, d, st, olabel)
        case ('displacement')
          call apply_displacement(gs(i), src, d, st)
        case default
          call apply_single(gs(i), src, d)
        end select
      end do
    end do

    if (len_trim(d%output%file) == 0) d%output%file = default_output(path)
    call check_cross(d, st)
    call deck_text(d, d%effective)
  end subroutine read_deck

  !> Render the effective deck (every value, defaults included) as namelist text that
  !! `read_deck` reads back to the same values. Lines are separated by LF.
  subroutine deck_text(d, text)
    type(deck_t), intent(in) :: d                         !< deck to render
    character(len=:), allocatable, intent(out) :: text    !< namelist text
    integer :: b, s, i
    character(len=*), parameter :: IND = '      '

    text = '! effective deck (every value, defaults included); source: '//trim(d%source)//NL
    text = text//'&scene title='//quote(trim(d%title))//', plane='// &
      quote(merge('strain', 'stress', d%plane_strain))//' /'//NL
    do b = 1, 2
      associate (y => d%body(b))
        text = text//'&body id='//i2s(y%id)//', x0='//r2s(y%x0)//', y0='//r2s(y%y0)// &
          ', width='//r2s(y%width)//', height='//r2s(y%height)//', nx='//i2s(y%nx)// &
          ', ny='//i2s(y%ny)//','//NL
        text = text//IND//'element='//quote(trim(element_names(max(1, min(2, y%element)))))// &
          ', young='//r2s(y%young)//', poisson='//r2s(y%poisson)//','//NL
        text = text//IND//'left='//quote(trim(bc_names(y%bc(SIDE_LEFT))))// &
          ', right='//quote(trim(bc_names(y%bc(SIDE_RIGHT))))// &
          ', top='//quote(trim(bc_names(y%bc(SIDE_TOP))))// &
          ', bottom='//quote(trim(bc_names(y%bc(SIDE_BOTTOM))))//' /'//NL
      end associate
    end do
    if (allocated(d%traction)) then
      do i = 1, d%ntraction
        associate (t => d%traction(i))
          text = text//'&traction body='//i2s(t%body)//', side='// &
            quote(trim(side_names(max(1, min(4, t%side)))))// &
            ', t0='//r2s(t%t0(1))//', '//r2s(t%t0(2))// &
            ', t1='//r2s(t%t1(1))//', '//r2s(t%t1(2))//' /'//NL
        end associate
      end do
    end if
    do b = 1, 2
      do s = 1, 4
        if (d%body(b)%bc(s) == BC_DISPLACEMENT) text = text//'&displacement body='//i2s(b)// &
          ', side='//quote(trim(side_names(s)))//', u='//r2s(d%body(b)%u_side(1, s))//', '// &
          r2s(d%body(b)%u_side(2, s))//' /'//NL
      end do
    end do
    text = text//'&contact gap_radius='//r2s(d%gap_radius)//', gap_center='//r2s(d%gap_center)//' /'//NL
    associate (v => d%solver)
      text = text//'&solver method='//quote(trim(v%method))//', robin_operator='// &
        quote(trim(v%robin_operator))//', alpha='//r2s(v%alpha)//', delta='//r2s(v%delta)// &
        ', tol='//r2s(v%tol)//','//NL
      text = text//IND//' stop='//quote(trim(v%stop))//', max_outer='//i2s(v%max_outer)// &
        ', factorization='//quote(trim(v%factorization))//', ordering='//quote(trim(v%ordering))// &
        ', acceleration='//quote(trim(v%acceleration))//','//NL
      text = text//IND//' inner_factor='//r2s(v%inner_factor)//', inner_rtol_min='// &
        r2s(v%inner_rtol_min)//', inner_rtol_max='//r2s(v%inner_rtol_max)// &
        ', inner_max_it='//i2s(v%inner_max_it)//', monolithic_rtol='//r2s(v%monolithic_rtol)//' /'//NL
    end associate
    text = text//'&output file='//quote(trim(d%output%file))//', checkpoint_every='// &
      i2s(d%output%checkpoint_every)//', progress_lines='//i2s(d%output%progress_lines)//' /'//NL
  end subroutine deck_text

  !> Print the effective deck as namelist text on `unit` (renders it if `d%effective` is unset).
  subroutine print_deck(d, unit)
    type(deck_t), intent(in) :: d   !< deck
    integer, intent(in) :: unit     !< open formatted output unit
    character(len=:), allocatable :: text
    integer :: p, q
    if (allocated(d%effective)) then
      text = d%effective
    else
      call deck_text(d, text)
    end if
    p = 1
    do while (p <= len(text))
      q = index(text(p:), NL)
      if (q == 0) then
        write (unit, '(a)') text(p:)
        exit
      end if
      write (unit, '(a)') text(p:p + q - 2)
      p = p + q
    end do
  end subroutine print_deck

  ! ============================================================================================
  ! Reading text and splitting it into groups and assignments
  ! ============================================================================================

  subroutine load_file(path, src)
    character(len=*), intent(in) :: path
    type(src_t), intent(out) :: src
    logical :: exists
    integer :: u, ios, n
    character(len=512) :: msg
    character(len=:), allocatable :: text

    if (len_trim(path) == 0) call fatal(EXIT_INPUT, 'no deck file given'//NL//deck_usage)
    inquire (file=path, exist=exists)
    if (.not. exists) call fatal(EXIT_INPUT, 'cannot open the deck file '''//path// &
      ''': no such file')
    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios, iomsg=msg)
    if (ios /= 0) call fatal(EXIT_INPUT, 'cannot open the deck file '''//path//''': '//trim(msg))
    inquire (unit=u, size=n)
    if (n < 0) n = 0
    allocate (character(len=n) :: text)
    if (n > 0) then
      read (u, iostat=ios, iomsg=msg) text
      if (ios /= 0) call fatal(EXIT_INPUT, 'cannot read the deck file '''//path//''': '//trim(msg))
    end if
    close (u)
    src%label = path
    src%is_file = .true.
    call split_lines(text, src%lines)
  end subroutine load_file

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
  subroutine parse_source(src, gs)
    type(src_t), intent(in) :: src
    type(grp_t), allocatable, intent(out) :: gs(:)
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
      if (bad > 0) call die_at(src, i, 'unterminated character string: the quote at column '// &
        i2s(bad)//' is not closed on this line')
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

    allocate (gs(0))
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
            ''' outside a namelist group; a group looks like &name var=value, ... /')
        else
          call die_at(src, lineof(p), 'syntax error: unexpected text '''//buf(p:q)// &
            ''' after the ''/'' that closes group &'//gs(ng)%name//' (line '// &
            i2s(gs(ng)%line)//'); a group looks like &name var=value, ... /')
        end if
      end if
      q = p + 1
      do while (q <= n)
        if (.not. is_ident(buf(q:q))) exit
        q = q + 1
      end do
      gname = lower(buf(p + 1:q - 1))
      if (len(gname) == 0) call die_at(src, lineof(p), 'syntax error: ''&'' must be followed '// &
        'by a group name (one of '//quoted_list(GROUP_NAMES, '&')//')')
      if (.not. is_letter(gname(1:1))) call die_at(src, lineof(p), 'syntax error: ''&'// &
        gname//''' is not a group name')
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
            i2s(lineof(r)))
        end if
        r = r + 1
      end do
      if (r > n) call die_at(src, lineof(p), 'syntax error: group &'//gname// &
        ' is not closed: a group ends with ''/''')
      allocate (tmp(ng + 1))
      tmp(1:ng) = gs
      call move_alloc(tmp, gs)
      ng = ng + 1
      gs(ng)%name = gname
      gs(ng)%text = buf(p:r)
      gs(ng)%line = lineof(p)
      call split_assignments(src, gs(ng), buf(q:r - 1), lineof(q:r - 1))
      p = r + 1
    end do
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
  subroutine split_assignments(src, g, body, lineof)
    type(src_t), intent(in) :: src
    type(grp_t), intent(inout) :: g
    character(len=*), intent(in) :: body
    integer, intent(in) :: lineof(:)
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
      if (len_trim(body) > 0) call die_at(src, lineof(first_nonblank(body)), &
        'syntax error in group &'//g%name//': expected name=value, found '''// &
        trim(adjustl(body))//'''')
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
          if (jp == 0) call die_at(src, lineof(j), 'syntax error in group &'//g%name// &
            ': unbalanced '')'' before ''=''')
          read (body(jp + 1:j - 1), *, iostat=ios) g%a(k)%sub
          if (ios /= 0 .or. g%a(k)%sub < 1 .or. verify(trim(adjustl(body(jp + 1:j - 1))), &
                                                           '0123456789') /= 0) &
            call die_at(src, lineof(j), 'in group &'//g%name//': bad subscript ('// &
            body(jp + 1:j - 1)//'); only a single index such as t0(2) is accepted')
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
      if (j + 1 > e) call die_at(src, lineof(eqs(k)), 'syntax error in group &'//g%name// &
        ': misplaced ''='' (no variable name before it)')
      if (.not. is_letter(body(j + 1:j + 1))) call die_at(src, lineof(j + 1), &
        'syntax error in group &'//g%name//': '''//body(j + 1:e)//''' is not a variable name')
      if (j >= 1) then
        if (body(j:j) /= ' ' .and. body(j:j) /= ',') call die_at(src, lineof(j + 1), &
          'syntax error in group &'//g%name//': '''//body(j:e)//''' is not a variable name')
      end if
      nstart(k) = j + 1
      g%a(k)%name = lower(body(j + 1:e))
      g%a(k)%line = lineof(j + 1)
    end do
    if (len_trim(body(1:nstart(1) - 1)) > 0) call die_at(src, lineof(first_nonblank(body)), &
      'syntax error in group &'//g%name//': expected name=value, found '''// &
      trim(adjustl(body(1:nstart(1) - 1)))//'''')
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
  ! Checking assignments against the variable tables
  ! ============================================================================================

  !> Check every assignment of `g`: known name, subscript, number and type of values.
  subroutine check_group(g, src, table)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: table
    integer :: k, typ, nval, nitem, i, rep, ios, star
    logical :: found
    type(str_t), allocatable :: items(:)
    character(len=:), allocatable :: tok, head
    real(wp) :: x
    integer :: m
    type(fpstate_t) :: fps

    do k = 1, g%nasg
      associate (a => g%a(k))
        call lookup(table, a%name, found, typ, nval)
        if (.not. found) call die_at(src, a%line, 'in group &'//g%name//': unknown variable '''// &
          a%name//'''; the variables of &'//g%name//' are '//var_list(table))
        head = 'in group &'//g%name//': '//a%name//' = '//a%value
        if (a%sub > 0) then
          if (nval == 1) call die_at(src, a%line, 'in group &'//g%name//': '//a%name// &
            ' is a single value and takes no subscript')
          if (a%sub > nval) call die_at(src, a%line, 'in group &'//g%name//': subscript '// &
            i2s(a%sub)//' of '//a%name//' is out of range (1 to '//i2s(nval)//')')
          nval = 1
        end if
        call split_items(a%value, items)
        nitem = 0
        do i = 1, size(items)
          tok = items(i)%s
          rep = 1
          star = scan(tok, '*')
          if (star > 0 .and. tok(1:1) /= '''' .and. tok(1:1) /= '"') then
            read (tok(1:star - 1), *, iostat=ios) rep
            if (ios /= 0 .or. rep < 1 .or. verify(tok(1:star - 1), '0123456789') /= 0) &
              call die_at(src, a%line, head//': bad repeat count in '''//tok//'''')
            tok = tok(star + 1:)
          end if
          nitem = nitem + rep
          if (len(tok) == 0) cycle   ! null value: leaves the variable unchanged
          select case (typ)
          case (T_INT)
            if (verify(tok, '+-0123456789') /= 0 .or. verify(tok(2:), '0123456789') /= 0 .or. &
                verify(tok, '+-') == 0) call die_at(src, a%line, head// &
              ': expected an integer, e.g. '//a%name//'=24, found '//tok)
            read (tok, *, iostat=ios) m
            if (ios /= 0) call die_at(src, a%line, head//': the integer '//tok//' is out of range')
          case (T_REAL)
            call fp_read_begin(fps)
            read (tok, *, iostat=ios) x
            call fp_read_end(fps)
            if (ios /= 0 .or. scan(tok, '''"/(),;') > 0 .or. verify(tok(1:1), '+-.0123456789') /= 0) then
              if (verify(lower(tok), '+-nafity') == 0 .and. ios == 0) then
                call die_at(src, a%line, head//': '//tok//' is not a finite real number')
              end if
              call die_at(src, a%line, head//': expected a real number, e.g. '// &
                a%name//'=1.5e6, found '//tok)
            end if
            if (.not. ieee_is_finite(x)) call die_at(src, a%line, head//': '//tok// &
              ' is not a finite real number')
          case (T_STR)
            if (.not. is_quoted(tok)) call die_at(src, a%line, head// &
              ': expected a quoted character string, e.g. '//a%name//'=''...'', found '//tok)
          end select
        end do
        if (nitem > nval) then
          if (nval == 1) then
            call die_at(src, a%line, head//': too many values ('//a%name//' takes one value)')
          else
            call die_at(src, a%line, head//': too many values ('//a%name//' takes '// &
              i2s(nval)//': the x and y components)')
          end if
        end if
      end associate
    end do
  end subroutine check_group

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

  subroutine lookup(table, name, found, typ, nval)
    character(len=*), intent(in) :: table, name
    logical, intent(out) :: found
    integer, intent(out) :: typ, nval
    integer :: p, q, c
    character(len=:), allocatable :: tok
    found = .false.
    typ = 0
    nval = 0
    p = 1
    do while (p <= len(table))
      call next_word(table, p, q)
      if (q < p) exit
      tok = table(p:q)
      c = index(tok, ':')
      if (tok(1:c - 1) == name) then
        found = .true.
        select case (tok(c + 1:))
        case ('i'); typ = T_INT; nval = 1
        case ('r'); typ = T_REAL; nval = 1
        case ('s'); typ = T_STR; nval = 1
        case ('r2'); typ = T_REAL; nval = 2
        end select
        return
      end if
      p = q + 1
    end do
  end subroutine lookup

  function var_list(table) result(s)
    character(len=*), intent(in) :: table
    character(len=:), allocatable :: s
    integer :: p, q
    s = ''
    p = 1
    do while (p <= len(table))
      call next_word(table, p, q)
      if (q < p) exit
      if (len(s) > 0) s = s//', '
      s = s//table(p:p + index(table(p:q), ':') - 2)
      p = q + 1
    end do
  end function var_list

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
  ! The groups
  ! ============================================================================================

  subroutine apply_single(g, src, d)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    select case (g%name)
    case ('scene')
      call apply_scene(g, src, d)
    case ('contact')
      call apply_contact(g, src, d)
    case ('solver')
      call apply_solver(g, src, d%solver)
    case ('output')
      call apply_output(g, src, d%output)
    end select
  end subroutine apply_single

  subroutine apply_scene(g, src, d)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    character(len=LLONG) :: title
    character(len=LSTR) :: plane
    character(len=LSTR) :: canon
    integer :: ios
    character(len=512) :: msg
    namelist /scene/ title, plane

    call check_group(g, src, V_SCENE)
    title = d%title
    plane = merge('strain', 'stress', d%plane_strain)
    read (g%text, nml=scene, iostat=ios, iomsg=msg)
    if (ios /= 0) call read_failed(g, src, msg)
    if (len_trim(title) > len(d%title)) call bad_value(g, src, 'title', '', &
      'is too long (at most '//i2s(len(d%title))//' characters)')
    call check_enum(g, src, 'plane', plane, E_PLANE, canon)
    d%title = title(1:len(d%title))
    d%plane_strain = (canon == 'strain')
  end subroutine apply_scene

  subroutine apply_contact(g, src, d)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    real(wp) :: gap_radius, gap_center
    integer :: ios
    type(fpstate_t) :: fps
    character(len=512) :: msg
    namelist /contact/ gap_radius, gap_center

    call check_group(g, src, V_CONTACT)
    gap_radius = d%gap_radius
    gap_center = d%gap_center
    call fp_read_begin(fps)
    read (g%text, nml=contact, iostat=ios, iomsg=msg)
    call fp_read_end(fps)
    if (ios /= 0) call read_failed(g, src, msg)
    if (gap_radius < 0.0_wp) call bad_value(g, src, 'gap_radius', r2s(gap_radius), &
      'must be >= 0 (0: no initial gap; R > 0: g0(x) = (x - gap_center)^2/(2R))')
    d%gap_radius = gap_radius
    d%gap_center = gap_center
  end subroutine apply_contact

  subroutine apply_solver(g, src, s)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(solver_cfg_t), intent(inout) :: s
    character(len=LSTR) :: method, robin_operator, stop, factorization, ordering, acceleration
    real(wp) :: alpha, delta, tol, inner_factor, inner_rtol_min, inner_rtol_max, monolithic_rtol
    integer :: max_outer, inner_max_it
    integer :: ios
    type(fpstate_t) :: fps
    character(len=512) :: msg
    namelist /solver/ method, robin_operator, alpha, delta, tol, stop, max_outer, &
      factorization, ordering, acceleration, inner_factor, inner_rtol_min, inner_rtol_max, &
      inner_max_it, monolithic_rtol

    call check_group(g, src, V_SOLVER)
    method = s%method
    robin_operator = s%robin_operator
    alpha = s%alpha
    delta = s%delta
    tol = s%tol
    stop = s%stop
    max_outer = s%max_outer
    factorization = s%factorization
    ordering = s%ordering
    acceleration = s%acceleration
    inner_factor = s%inner_factor
    inner_rtol_min = s%inner_rtol_min
    inner_rtol_max = s%inner_rtol_max
    inner_max_it = s%inner_max_it
    monolithic_rtol = s%monolithic_rtol
    call fp_read_begin(fps)
    read (g%text, nml=solver, iostat=ios, iomsg=msg)
    call fp_read_end(fps)
    if (ios /= 0) call read_failed(g, src, msg)

    call check_enum(g, src, 'method', method, E_METHOD, s%method)
    call check_enum(g, src, 'robin_operator', robin_operator, E_OPERATOR, s%robin_operator)
    call check_enum(g, src, 'stop', stop, E_STOP, s%stop)
    call check_enum(g, src, 'factorization', factorization, E_FACT, s%factorization)
    call check_enum(g, src, 'ordering', ordering, E_ORDERING, s%ordering)
    call check_enum(g, src, 'acceleration', acceleration, E_ACCEL, s%acceleration)
    if (alpha < 0.0_wp) call bad_value(g, src, 'alpha', r2s(alpha), 'must be >= 0')
    if (s%robin_operator == 'constant' .and. .not. alpha > 0.0_wp) call bad_value(g, src, &
      'alpha', r2s(alpha), 'must be > 0 when robin_operator=''constant''')
    if (.not. (delta > 0.0_wp .and. delta <= 1.0_wp)) call bad_value(g, src, 'delta', &
      r2s(delta), 'is out of range: the relaxation must satisfy 0 < delta <= 1')
    if (.not. tol > 0.0_wp) call bad_value(g, src, 'tol', r2s(tol), 'must be > 0')
    if (max_outer < 1) call bad_value(g, src, 'max_outer', i2s(max_outer), 'must be >= 1')
    if (.not. inner_factor > 0.0_wp) call bad_value(g, src, 'inner_factor', r2s(inner_factor), &
      'must be > 0')
    if (.not. (inner_rtol_min > 0.0_wp .and. inner_rtol_min < 1.0_wp)) call bad_value(g, src, &
      'inner_rtol_min', r2s(inner_rtol_min), 'must satisfy 0 < inner_rtol_min < 1')
    if (.not. (inner_rtol_max > 0.0_wp .and. inner_rtol_max < 1.0_wp)) call bad_value(g, src, &
      'inner_rtol_max', r2s(inner_rtol_max), 'must satisfy 0 < inner_rtol_max < 1')
    if (inner_rtol_max < inner_rtol_min) call bad_value(g, src, 'inner_rtol_max', &
      r2s(inner_rtol_max), 'must be >= inner_rtol_min = '//r2s(inner_rtol_min))
    if (inner_max_it < 1) call bad_value(g, src, 'inner_max_it', i2s(inner_max_it), 'must be >= 1')
    if (.not. (monolithic_rtol > 0.0_wp .and. monolithic_rtol < 1.0_wp)) call bad_value(g, src, &
      'monolithic_rtol', r2s(monolithic_rtol), 'must satisfy 0 < monolithic_rtol < 1')
    s%alpha = alpha
    s%delta = delta
    s%tol = tol
    s%max_outer = max_outer
    s%inner_factor = inner_factor
    s%inner_rtol_min = inner_rtol_min
    s%inner_rtol_max = inner_rtol_max
    s%inner_max_it = inner_max_it
    s%monolithic_rtol = monolithic_rtol
  end subroutine apply_solver

  subroutine apply_output(g, src, o)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(output_cfg_t), intent(inout) :: o
    character(len=LLONG) :: file
    integer :: checkpoint_every, progress_lines
    integer :: ios
    character(len=512) :: msg
    namelist /output/ file, checkpoint_every, progress_lines

    call check_group(g, src, V_OUTPUT)
    file = o%file
    checkpoint_every = o%checkpoint_every
    progress_lines = o%progress_lines
    read (g%text, nml=output, iostat=ios, iomsg=msg)
    if (ios /= 0) call read_failed(g, src, msg)
    file = adjustl(file)
    if (len_trim(file) > len(o%file)) call bad_value(g, src, 'file', '', &
      'is too long (at most '//i2s(len(o%file))//' characters)')
    if (checkpoint_every < 0) call bad_value(g, src, 'checkpoint_every', i2s(checkpoint_every), &
      'must be >= 0 (0: no checkpoints)')
    if (progress_lines < 0) call bad_value(g, src, 'progress_lines', i2s(progress_lines), &
      'must be >= 0')
    o%file = file(1:len(o%file))
    o%checkpoint_every = checkpoint_every
    o%progress_lines = progress_lines
  end subroutine apply_output

  !> A &body in the deck file: a new body.
  subroutine new_body(g, src, d, st)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    integer :: id
    logical :: found
    type(body_cfg_t) :: fresh

    call check_group(g, src, V_BODY)
    if (st%nbody == 2) call die_at(src, g%line, 'in group &body: a third &body group; a deck '// &
      'has exactly two bodies, with ids 1 and 2 (the others are at lines '// &
      i2s(st%body_line(1))//' and '//i2s(st%body_line(2))//')')
    call find_int(g, 'id', id, found)
    if (.not. found) call die_at(src, g%line, 'in group &body: no id; give id=1 or id=2')
    if (id /= 1 .and. id /= 2) call bad_value(g, src, 'id', i2s(id), &
      'is not a body id: the two bodies have ids 1 and 2')
    if (d%body(id)%id /= 0) call bad_value(g, src, 'id', i2s(id), &
      'is used twice (also by the &body at line '//i2s(st%body_line(id))// &
      '); the two bodies must have ids 1 and 2')
    fresh%id = id
    call apply_body(g, src, fresh, d%body(id))
    st%nbody = st%nbody + 1
    st%body_line(id) = g%line
    st%body_at(id)%s = '&body at line '//i2s(g%line)
  end subroutine new_body

  !> A &body on the command line: changes the existing body with that id.
  subroutine override_body(g, src, d, st)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    integer :: id
    logical :: found
    type(body_cfg_t) :: copy

    call check_group(g, src, V_BODY)
    call find_int(g, 'id', id, found)
    if (.not. found) call die_at(src, g%line, 'in group &body: an override of &body must name '// &
      'the body it changes with id=1 or id=2, e.g. ''&body id=2, young=1e9 /''')
    if (id /= 1 .and. id /= 2) call bad_value(g, src, 'id', i2s(id), &
      'is not a body id: the two bodies have ids 1 and 2')
    copy = d%body(id)
    call apply_body(g, src, copy, d%body(id))
    st%body_at(id)%s = st%body_at(id)%s//', changed by '//src%label
  end subroutine override_body

  !> Read a &body group into a copy of `b0` (its current values) and store it in `b`.
  subroutine apply_body(g, src, b0, b)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(body_cfg_t), intent(in) :: b0
    type(body_cfg_t), intent(inout) :: b
    integer :: id, nx, ny
    real(wp) :: x0, y0, width, height, young, poisson
    character(len=LSTR) :: element, left, right, top, bottom
    character(len=LSTR) :: canon, cond(4)
    integer :: ios, s, code
    type(fpstate_t) :: fps
    character(len=512) :: msg
    namelist /body/ id, x0, y0, width, height, nx, ny, element, young, poisson, &
      left, right, top, bottom

    id = b0%id
    x0 = b0%x0
    y0 = b0%y0
    width = b0%width
    height = b0%height
    nx = b0%nx
    ny = b0%ny
    element = element_names(b0%element)
    young = b0%young
    poisson = b0%poisson
    left = bc_names(b0%bc(SIDE_LEFT))
    right = bc_names(b0%bc(SIDE_RIGHT))
    bottom = bc_names(b0%bc(SIDE_BOTTOM))
    top = bc_names(b0%bc(SIDE_TOP))
    call fp_read_begin(fps)
    read (g%text, nml=body, iostat=ios, iomsg=msg)
    call fp_read_end(fps)
    if (ios /= 0) call read_failed(g, src, msg)

    if (.not. width > 0.0_wp) call bad_value(g, src, 'width', r2s(width), 'must be > 0')
    if (.not. height > 0.0_wp) call bad_value(g, src, 'height', r2s(height), 'must be > 0')
    if (nx < 1) call bad_value(g, src, 'nx', i2s(nx), 'must be >= 1 (cells along x)')
    if (ny < 1) call bad_value(g, src, 'ny', i2s(ny), 'must be >= 1 (cells along y)')
    if (.not. young > 0.0_wp) call bad_value(g, src, 'young', r2s(young), &
      'must be > 0 (Young''s modulus)')
    if (poisson >= 0.5_wp) call bad_value(g, src, 'poisson', r2s(poisson), 'is out of range: '// &
      'it must satisfy -1 < poisson < 0.5; poisson >= 0.5 (an incompressible material) is '// &
      'rejected: this displacement formulation cannot model it')
    if (poisson <= -1.0_wp) call bad_value(g, src, 'poisson', r2s(poisson), 'is out of range: '// &
      'it must satisfy -1 < poisson < 0.5')
    call check_enum(g, src, 'element', element, E_ELEMENT, canon)
    b%element = merge(ELEM_Q1, ELEM_P1, canon == 'Q1')
    call check_enum(g, src, 'left', left, E_COND, cond(SIDE_LEFT))
    call check_enum(g, src, 'right', right, E_COND, cond(SIDE_RIGHT))
    call check_enum(g, src, 'bottom', bottom, E_COND, cond(SIDE_BOTTOM))
    call check_enum(g, src, 'top', top, E_COND, cond(SIDE_TOP))

    b%id = b0%id
    b%x0 = x0
    b%y0 = y0
    b%width = width
    b%height = height
    b%nx = nx
    b%ny = ny
    b%young = young
    b%poisson = poisson
    b%u_side = b0%u_side
    do s = 1, 4
      code = index_of(E_COND, cond(s)) - 1
      b%bc(s) = code
      if (code /= BC_DISPLACEMENT) b%u_side(:, s) = 0.0_wp
    end do
  end subroutine apply_body

  !> A &traction group (deck or override): appends a traction.
  subroutine add_traction(g, src, d, st, origin)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    character(len=*), intent(in) :: origin
    integer :: body
    character(len=LSTR) :: side, canon
    real(wp) :: t0(2), t1(2)
    integer :: ios
    type(fpstate_t) :: fps
    character(len=512) :: msg
    type(traction_cfg_t), allocatable :: tmp(:)
    type(str_t), allocatable :: wtmp(:)
    namelist /traction/ body, side, t0, t1

    call check_group(g, src, V_TRACTION)
    body = 0
    side = ''
    t0 = 0.0_wp
    t1 = 0.0_wp
    call fp_read_begin(fps)
    read (g%text, nml=traction, iostat=ios, iomsg=msg)
    call fp_read_end(fps)
    if (ios /= 0) call read_failed(g, src, msg)
    call body_and_side(g, src, body, side, canon)

    allocate (tmp(d%ntraction + 1), wtmp(d%ntraction + 1))
    tmp(1:d%ntraction) = d%traction(1:d%ntraction)
    wtmp(1:d%ntraction) = st%trac_at(1:d%ntraction)
    call move_alloc(tmp, d%traction)
    call move_alloc(wtmp, st%trac_at)
    d%ntraction = d%ntraction + 1
    d%traction(d%ntraction)%body = body
    d%traction(d%ntraction)%side = index_of(E_SIDE, canon)
    d%traction(d%ntraction)%t0 = t0
    d%traction(d%ntraction)%t1 = t1
    st%trac_at(d%ntraction)%s = origin
  end subroutine add_traction

  !> A &displacement group (deck or override): prescribes a displacement on a side.
  subroutine apply_displacement(g, src, d, st)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    integer :: body, s
    character(len=LSTR) :: side, canon
    real(wp) :: u(2)
    integer :: ios
    type(fpstate_t) :: fps
    character(len=512) :: msg
    namelist /displacement/ body, side, u

    call check_group(g, src, V_DISPLACEMENT)
    body = 0
    side = ''
    u = 0.0_wp
    call fp_read_begin(fps)
    read (g%text, nml=displacement, iostat=ios, iomsg=msg)
    call fp_read_end(fps)
    if (ios /= 0) call read_failed(g, src, msg)
    call body_and_side(g, src, body, side, canon)
    s = index_of(E_SIDE, canon)
    if (d%body(body)%bc(s) == BC_CONTACT) call bad_value(g, src, 'side', "'"//trim(canon)//"'", &
      'is the contact side of body '//i2s(body)//'; a contact side cannot have a '// &
      'prescribed displacement')
    if (src%is_file) then
      if (st%disp_line(s, body) > 0) call die_at(src, g%line, 'in group &displacement: side '''// &
        trim(canon)//''' of body '//i2s(body)//' already has a prescribed displacement (line '// &
        i2s(st%disp_line(s, body))//')')
      st%disp_line(s, body) = g%line
    end if
    d%body(body)%bc(s) = BC_DISPLACEMENT
    d%body(body)%u_side(:, s) = u
  end subroutine apply_displacement

  !> Check the body= and side= of a &traction or &displacement.
  subroutine body_and_side(g, src, body, side, canon)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    integer, intent(in) :: body
    character(len=*), intent(in) :: side
    character(len=*), intent(out) :: canon
    integer :: k
    k = find_asg(g, 'body')
    if (k == 0) then
      call die_at(src, g%line, 'in group &'//g%name//': no body; give body=1 or body=2')
    else if (len_trim(g%a(k)%value) == 0) then
      call die_at(src, g%line, 'in group &'//g%name//': no body; give body=1 or body=2')
    end if
    if (body /= 1 .and. body /= 2) call bad_value(g, src, 'body', i2s(body), &
      'does not exist: the bodies have ids 1 and 2')
    if (len_trim(side) == 0) call die_at(src, g%line, 'in group &'//g%name//': no side; give '// &
      'side='//quoted_list(E_SIDE, ''))
    call check_enum(g, src, 'side', side, E_SIDE, canon)
  end subroutine body_and_side

  ! ============================================================================================
  ! Cross-field checks
  ! ============================================================================================

  subroutine check_cross(d, st)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    integer :: b, s, nc, cs(2), i, n1, n2
    character(len=:), allocatable :: p, lst, what
    real(wp) :: scale, tol, c1, c2, a1, a2, e1, e2
    logical :: fixed, roll_h, roll_v, horizontal

    p = st%path//': '
    do b = 1, 2
      nc = count(d%body(b)%bc == BC_CONTACT)
      if (nc /= 1) then
        lst = ''
        do s = 1, 4
          if (d%body(b)%bc(s) == BC_CONTACT) lst = lst//merge(', ', '  ', len(lst) > 0)//trim(side_names(s))
        end do
        if (nc == 0) then
          call fatal(EXIT_INPUT, p//'body '//i2s(b)//' ('//st%body_at(b)%s//') has no '// &
            '''contact'' side; each body needs exactly one ('//side_list(d%body(b))//')')
        else
          call fatal(EXIT_INPUT, p//'body '//i2s(b)//' ('//st%body_at(b)%s//') has '//i2s(nc)// &
            ' ''contact'' sides ('//trim(adjustl(lst))//'); each body needs exactly one')
        end if
      end if
      cs(b) = findloc(d%body(b)%bc, BC_CONTACT, dim=1)
    end do

    if (.not. ((cs(1) == SIDE_BOTTOM .and. cs(2) == SIDE_TOP) .or. &
               (cs(1) == SIDE_TOP .and. cs(2) == SIDE_BOTTOM) .or. &
               (cs(1) == SIDE_LEFT .and. cs(2) == SIDE_RIGHT) .or. &
               (cs(1) == SIDE_RIGHT .and. cs(2) == SIDE_LEFT))) &
      call fatal(EXIT_INPUT, p//'the contact sides do not face each other: body 1 ('// &
      st%body_at(1)%s//') has its contact on its '//trim(side_names(cs(1)))//' side, body 2 ('// &
      st%body_at(2)%s//') on its '//trim(side_names(cs(2)))//' side; the pairs allowed '// &
      '(body 1/body 2) are bottom/top, top/bottom, left/right and right/left')

    scale = 0.0_wp
    do b = 1, 2
      associate (y => d%body(b))
        scale = max(scale, abs(y%x0), abs(y%x0 + y%width), abs(y%y0), abs(y%y0 + y%height), &
                    y%width, y%height)
      end associate
    end do
    tol = 1.0e-9_wp * scale
    horizontal = (cs(1) == SIDE_BOTTOM .or. cs(1) == SIDE_TOP)
    call side_line(d%body(1), cs(1), c1, a1, e1)
    call side_line(d%body(2), cs(2), c2, a2, e2)
    if (abs(c1 - c2) > tol .or. abs(a1 - a2) > tol .or. abs(e1 - e2) > tol) then
      if (horizontal) then
        what = 'body 1''s '//trim(side_names(cs(1)))//' side is y = '//r2s(c1)//' for x from '// &
          r2s(a1)//' to '//r2s(e1)//', body 2''s '//trim(side_names(cs(2)))//' side is y = '// &
          r2s(c2)//' for x from '//r2s(a2)//' to '//r2s(e2)
      else
        what = 'body 1''s '//trim(side_names(cs(1)))//' side is x = '//r2s(c1)//' for y from '// &
          r2s(a1)//' to '//r2s(e1)//', body 2''s '//trim(side_names(cs(2)))//' side is x = '// &
          r2s(c2)//' for y from '//r2s(a2)//' to '//r2s(e2)
      end if
      call fatal(EXIT_INPUT, p//'the contact sides do not coincide: '//what// &
        '; they must be the same segment (within 1e-9 relative); check x0, y0, width, height')
    end if
    if (horizontal) then
      n1 = d%body(1)%nx
      n2 = d%body(2)%nx
    else
      n1 = d%body(1)%ny
      n2 = d%body(2)%ny
    end if
    if (n1 /= n2) call fatal(EXIT_INPUT, p//'the contact sides do not match node for node: '// &
      'body 1 has '//merge('nx', 'ny', horizontal)//' = '//i2s(n1)//' cells along its '// &
      trim(side_names(cs(1)))//' side, body 2 has '//merge('nx', 'ny', horizontal)//' = '// &
      i2s(n2)//' along its '//trim(side_names(cs(2)))//' side; the meshes need the same '// &
      'number of cells along the contact line')

    do b = 1, 2
      associate (y => d%body(b))
        fixed = any(y%bc == BC_CLAMPED .or. y%bc == BC_DISPLACEMENT)
        roll_h = y%bc(SIDE_TOP) == BC_ROLLER .or. y%bc(SIDE_BOTTOM) == BC_ROLLER
        roll_v = y%bc(SIDE_LEFT) == BC_ROLLER .or. y%bc(SIDE_RIGHT) == BC_ROLLER
        if (.not. (fixed .or. (roll_h .and. roll_v))) call fatal(EXIT_INPUT, p//'body '// &
          i2s(b)//' ('//st%body_at(b)%s//') is not supported against rigid motion ('// &
          side_list(y)//'): it needs a ''clamped'' side, a &displacement side, or ''roller'' '// &
          'on one horizontal (top/bottom) and one vertical (left/right) side; the contact '// &
          'side does not count')
      end associate
    end do

    do i = 1, d%ntraction
      associate (t => d%traction(i))
        s = d%body(t%body)%bc(t%side)
        if (s == BC_CONTACT) call fatal(EXIT_INPUT, p//'the &traction at '//st%trac_at(i)%s// &
          ' loads side '''//trim(side_names(t%side))//''' of body '//i2s(t%body)//', which is '// &
          'its contact side; a contact side carries only contact forces')
        if (s == BC_CLAMPED .or. s == BC_DISPLACEMENT) call warn(p// &
          'the &traction at '//st%trac_at(i)%s//' loads side '''//trim(side_names(t%side))// &
          ''' of body '//i2s(t%body)//', which has a prescribed displacement ('''// &
          trim(bc_names(s))//'''); that traction has no effect')
      end associate
    end do
  end subroutine check_cross

  !> A side as a segment: the fixed coordinate c and the extent [a, e] along the side.
  subroutine side_line(b, s, c, a, e)
    type(body_cfg_t), intent(in) :: b
    integer, intent(in) :: s
    real(wp), intent(out) :: c, a, e
    select case (s)
    case (SIDE_LEFT, SIDE_RIGHT)
      c = merge(b%x0, b%x0 + b%width, s == SIDE_LEFT)
      a = b%y0
      e = b%y0 + b%height
    case default
      c = merge(b%y0, b%y0 + b%height, s == SIDE_BOTTOM)
      a = b%x0
      e = b%x0 + b%width
    end select
  end subroutine side_line

  function side_list(b) result(s)
    type(body_cfg_t), intent(in) :: b
    character(len=:), allocatable :: s
    s = 'left='''//trim(bc_names(b%bc(SIDE_LEFT)))//''', right='''//trim(bc_names(b%bc(SIDE_RIGHT)))// &
      ''', top='''//trim(bc_names(b%bc(SIDE_TOP)))//''', bottom='''//trim(bc_names(b%bc(SIDE_BOTTOM)))//''''
  end function side_list

  function default_output(path) result(f)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: f, base
    integer :: k
    k = index(path, '/', back=.true.)
    base = trim(path(k + 1:))
    k = index(base, '.', back=.true.)
    if (k > 1) base = base(1:k - 1)
    if (len(base) == 0) base = 'deck'
    f = 'results/'//base//'.h5'
  end function default_output

  ! ============================================================================================
  ! Errors
  ! ============================================================================================

  !> Fatal error at a line of a source, with the line echoed.
  subroutine die_at(src, line, msg)
    type(src_t), intent(in) :: src
    integer, intent(in) :: line
    character(len=*), intent(in) :: msg
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
    call fatal(EXIT_INPUT, m)
  end subroutine die_at

  !> Fatal error on the value of one variable of a group (at the line where it is set).
  subroutine bad_value(g, src, name, shown, why)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: name   ! variable
    character(len=*), intent(in) :: shown  ! its value, used when it is not set in this group
    character(len=*), intent(in) :: why
    integer :: k
    k = find_asg(g, name)
    if (k > 0) then
      call die_at(src, g%a(k)%line, 'in group &'//g%name//': '//name//' = '//g%a(k)%value// &
        ' '//why)
    else
      call die_at(src, g%line, 'in group &'//g%name//': '//name//' = '//shown// &
        ' (not set in this group) '//why)
    end if
  end subroutine bad_value

  !> An enumeration: `value` must be one of the blank-separated `allowed` (any case).
  subroutine check_enum(g, src, name, value, allowed, canon)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: name, value, allowed
    character(len=*), intent(out) :: canon
    integer :: k
    k = index_of(allowed, trim(adjustl(value)))
    if (k == 0) call bad_value(g, src, name, quote(trim(value)), 'is not allowed; the allowed '// &
      'values are '//quoted_list(allowed, ''))
    canon = word(allowed, k)
  end subroutine check_enum

  subroutine unknown_group(g, src)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    call die_at(src, g%line, 'unknown group &'//g%name//'; the groups are '// &
      quoted_list(GROUP_NAMES, '&'))
  end subroutine unknown_group

  !> The namelist READ failed although check_group accepted every assignment.
  subroutine read_failed(g, src, msg)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: msg
    call die_at(src, g%line, 'in group &'//g%name//': cannot read the group ('//trim(msg)//')')
  end subroutine read_failed

end module deck
