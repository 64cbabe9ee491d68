!> Tests of module deck on good input: the default deck's values, the round trip
!! (print_deck output read back gives identical values), override precedence and
!! semantics, defaults, a few namelist forms (case, repeat counts, quotes, comments), and
!! the Markdown reference table of a group (cells, required, forms, escaping); the contact
!! pairs in both forms and their bad input. A bad deck is read in this process: read_deck
!! returns ERR_INPUT (exit code 1) and a message that names the deck file first and holds the
!! expected text (tests/system/test_bad_input.sh runs the whole program on more).
program test_deck
  use kinds, only: wp
  use config
  use deck, only: read_deck, print_deck, deck_text
  use errors, only: error_t, exit_code, ERR_INPUT, EXIT_INPUT
  use namelist_vars, only: vars_t, str_t, reference_table, render_group
  use testing, only: report, test_summary, write_file
  implicit none (type, external)
  type(deck_t) :: d, e
  character(len=512) :: tmp
  character(len=200) :: none(0)
  character(len=200) :: ov(6)
  character(len=:), allocatable :: t1, t2
  character(len=*), parameter :: NL = achar(10)
  real(wp) :: r

  call random_number(r)
  write (tmp, '(a,i0)') '/tmp/test_deck_', int(r * 1.0e9_wp)

  ! ---- the default deck (the seed's scene) ---------------------------------------------
  call read_good('inputs/default.nml', none, d)
  call check(d%body(1)%id == 1 .and. d%body(2)%id == 2, 'default: body ids 1 and 2')
  call check(d%body(1)%nx == 24 .and. d%body(1)%ny == 16 .and. d%body(2)%nx == 24 .and. &
             d%body(2)%ny == 16, 'default: 24x16 cells per body')
  call check(d%body(1)%young == 2.1e11_wp .and. d%body(2)%poisson == 0.277_wp, &
             'default: young = 2.1e11, poisson = 0.277 exactly')
  call check(d%body(1)%y0 == 1.0_wp .and. d%body(2)%y0 == 0.0_wp .and. d%body(1)%width == 3.0_wp, &
             'default: geometry (0,3)x(1,2) over (0,3)x(0,1)')
  call check(all(d%body(1)%bc(1:4) == [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE]), &
             'default: body 1 sides clamped/free/contact/free (left,right,bottom,top)')
  call check(all(d%body(2)%bc(1:4) == [BC_CLAMPED, BC_FREE, BC_FREE, BC_CONTACT]), &
             'default: body 2 sides clamped/free/free/contact')
  call check(d%ntraction == 2, 'default: two tractions')
  if (d%ntraction == 2) then
    call check(d%traction(1)%body == 1 .and. d%traction(1)%side == SIDE_TOP .and. &
               all(d%traction(1)%t0(1:2) == [0.0_wp, -3.0e6_wp]) .and. &
               all(d%traction(1)%t1(1:2) == [0.0_wp, -1.0e6_wp]), 'default: top traction t0, t1')
    call check(d%traction(2)%side == SIDE_RIGHT .and. all(d%traction(2)%t0(1:2) == [0.0_wp, 2.0e6_wp]) &
               .and. all(d%traction(2)%t1 == 0.0_wp), 'default: right traction, t1 defaults to 0')
  end if
  call check(d%plane_strain, 'default: plane strain')
  call check(d%solver%method == METHOD_ROBIN .and. d%solver%delta == 0.95_wp .and. &
             d%solver%tol == 1.0e-8_wp .and. d%solver%max_outer == 800, 'default: solver values')
  call check(d%output%file == 'results/default.h5', 'default: output file')
  call check(allocated(d%effective), 'default: effective deck text stored')

  ! ---- round trip of the default deck ----------------------------------------------------
  call round_trip(d, 'default deck')

  ! ---- overrides -----------------------------------------------------------------------------
  ov(1) = '&solver delta=0.5 /'
  ov(2) = '&body id=2, young=1e9 /'
  ov(3) = '&solver delta=0.7, robin_operator=''constant'', alpha=2.5e-12 /'
  ov(4) = '&traction body=2, side=''bottom'', t0=0.0, 1.0e5 /'
  ov(5) = '&displacement body=2, side=''right'', u=0.0, -1.0e-4 /  &scene plane=''stress'' /'
  ov(6) = '&body id=1, element=''p1'' /'
  call read_good('inputs/default.nml', ov, e)
  call check(e%solver%delta == 0.7_wp, 'override: later override wins (delta = 0.7)')
  call check(e%solver%robin_operator == ROBIN_CONSTANT .and. e%solver%alpha == 2.5e-12_wp, &
             'override: robin_operator and alpha')
  call check(e%body(2)%young == 1.0e9_wp .and. e%body(1)%young == 2.1e11_wp, &
             'override: &body id=2 changes body 2 only')
  call check(e%body(2)%nx == 24 .and. e%body(2)%poisson == 0.277_wp .and. &
             e%body(2)%bc(SIDE_TOP) == BC_CONTACT, 'override: other values of body 2 kept')
  call check(e%ntraction == 3, 'override: &traction appends (3 tractions)')
  if (e%ntraction == 3) call check(e%traction(3)%body == 2 .and. e%traction(3)%side == SIDE_BOTTOM &
                                   .and. e%traction(3)%t0(2) == 1.0e5_wp, 'override: appended traction')
  call check(e%body(2)%bc(SIDE_RIGHT) == BC_DISPLACEMENT .and. &
             all(e%body(2)%u_side(1:2, SIDE_RIGHT) == [0.0_wp, -1.0e-4_wp]), &
             'override: &displacement sets the side and its vector')
  call check(.not. e%plane_strain, 'override: two groups in one override (plane stress)')
  call check(e%body(1)%element == ELEM_P1 .and. e%body(2)%element == ELEM_Q1, &
             'override: element, case-insensitive')
  call round_trip(e, 'deck with overrides')

  ! ---- defaults, namelist forms ----------------------------------------------------------
  call write_file(trim(tmp)//'_my_case.nml', [character(len=120) :: &
    '! minimal deck: only the bodies', &
    '&BODY ID=1, Y0=1.0, NX=4, NY=2, LEFT=''Clamped'', Bottom="contact" / &body id=2,', &
    '  nx=4, ny=2, left=''roller'', bottom=''roller'', top=''contact'', young=1.5e9 /', &
    '&scene title=''a!b, it''''s "quoted" / here'' /  ! comment with a quote '' and a /', &
    '&traction body=1, side=''top'', t0=2*-1.0e6 /', &
    '&traction body=1, side=''top'', t0(2)=5.0, t1=, 3.0 /'])
  call read_good(trim(tmp)//'_my_case.nml', none, e)
  call check(e%output%file == 'results/'//trim(tmp(6:))//'_my_case.h5', &
             'defaults: output file results/<deck basename>.h5 ('//trim(e%output%file)//')')
  call check(e%body(1)%width == 1.0_wp .and. e%body(1)%poisson == 0.3_wp .and. &
             e%solver%delta == 0.5_wp .and. e%solver%robin_operator == ROBIN_HARMONIC .and. &
             e%pair(1)%gap_radius == 0.0_wp, 'defaults: config.f90 values (harmonic at delta 0.5)')
  call check(all(e%body(2)%bc(1:4) == [BC_ROLLER, BC_FREE, BC_ROLLER, BC_CONTACT]), &
             'forms: upper-case names, mixed-case values, double quotes, two groups on a line')
  call check(e%title == 'a!b, it''s "quoted" / here', 'forms: quotes, ! and / inside a string')
  call check(all(e%traction(1)%t0(1:2) == -1.0e6_wp), 'forms: repeat count 2*-1.0e6')
  call check(all(e%traction(2)%t0(1:2) == [0.0_wp, 5.0_wp]) .and. all(e%traction(2)%t1(1:2) == [0.0_wp, 3.0_wp]), &
             'forms: subscript t0(2)= and a null value t1=, 3.0')
  call round_trip(e, 'minimal deck')
  call delete_file(trim(tmp)//'_my_case.nml')

  ! ---- exact round trip of awkward reals -----------------------------------------------------
  ! young: the largest modulus accepted (the double below MODULUS_MAX); huge(1.0) is refused
  ! before the elastic law is computed, which it makes overflow (below)
  call write_file(trim(tmp)//'_reals.nml', [character(len=200) :: &
    '&body id=1, x0=-0.1, y0=0.30000000000000004, width=1.2345678901234567e11, height=7e-300,', &
    '  nx=1, ny=1, left=''clamped'', bottom=''contact'', young=1.3407807929942594e148, poisson=-0.999999 /', &
    '&body id=2, x0=-0.1, y0=-1.0, width=1.2345678901234567e11, height=1.0, nx=1, ny=1,', &
    '  left=''clamped'', top=''contact'', poisson=0.49999999999999994 /', &
    '&contact gap_radius=123456.7, gap_center=-2.5e-5 /'])
  call read_good(trim(tmp)//'_reals.nml', none, e)
  call check(e%body(1)%y0 == 0.30000000000000004_wp .and. e%body(1)%young == nearest(MODULUS_MAX, -1.0_wp) &
             .and. e%body(2)%poisson == 0.49999999999999994_wp, 'reals: read exactly')
  call round_trip(e, 'awkward reals')
  call delete_file(trim(tmp)//'_reals.nml')
  call refused('young_huge', [character(len=200) :: &
    '&body id=1, y0=1.0, nx=1, ny=1, left=''clamped'', bottom=''contact'',', &
    '  young=1.7976931348623157e308, poisson=-0.999999 /', &
    '&body id=2, nx=1, ny=1, left=''clamped'', top=''contact'' /'], &
    ':2: in group &body: young = 1.7976931348623157e308 is outside [7.458E-149, 1.341E+148]')
  call refused('young_max', [character(len=200) :: &
    '&body id=1, y0=1.0, nx=1, ny=1, left=''clamped'', bottom=''contact'', young=1.3407807929942596e148 /', &
    '&body id=2, nx=1, ny=1, left=''clamped'', top=''contact'' /'], &
    ':1: in group &body: young = 1.3407807929942596e148 is outside')

  call test_pairs()

  call deck_text(d, t1)
  call deck_text(d, t2)
  call check(t1 == t2 .and. t1 == d%effective, 'deck_text is deterministic and equals d%effective')

  ! ---- the reference table of a group (namelist_input%reference_table) -----------------------
  block
    type(vars_t) :: v, forms(2)
    integer, target :: n, code
    real(wp), target :: x, p(2)
    character(len=8), target :: s
    integer, target :: ip(2)
    character(len=6), target :: sp(2)
    character(len=:), allocatable :: tab
    n = 3
    code = 0
    x = 2.5e11_wp
    p = [1.0_wp, -0.5_wp]
    s = 'ab'
    call v%int('n', n, doc='count', range='>= 1', required=.true.)
    call v%real('x', x, unit='[stress]', range='> 0', doc='a | b')
    call v%pair('p', p, unit='[length]', doc='position')
    call v%str('s', s)
    call v%enum('c', code, 'one two')
    ip = [3, 1]
    sp = ['top   ', 'rim   ']
    call v%ints('ip', ip, range='two ids', doc='bodies')
    call v%strs('sp', sp, doc='groups')
    call forms(1)%int('n', n)
    call forms(1)%real('x', x)
    call forms(2)%int('n', n)
    call forms(2)%pair('p', p)
    tab = reference_table(v, forms, [str_t('A'), str_t('B')])
    call check(index(tab, '| variable | type | default | unit | allowed values | description |'//NL// &
                     '| --- | --- | --- | --- | --- | --- |'//NL) == 1, 'reference table: header')
    call check(index(tab, NL//'| `n` | integer | required | | >= 1 | count |'//NL) > 0, &
               'reference table: a required integer with its range')
    call check(index(tab, NL//'| `x` | real | `2.5e11` | [stress] | > 0 | *A only:* a \| b |'//NL) > 0, &
               'reference table: a real with its unit, form and an escaped bar')
    call check(index(tab, NL//'| `p` | real pair (x, y) | `1.0, -0.5` | [length] | | *B only:* position |'//NL) > 0, &
               'reference table: a pair')
    call check(index(tab, NL//'| `s` | string (at most 8 characters) | `''ab''` | | | |'//NL) > 0, &
               'reference table: a string without a description')
    call check(index(tab, NL//'| `c` | choice | none | | `''one''`, `''two''` | |'//NL) > 0, &
               'reference table: a choice without a value')
    call check(index(tab, NL//'| `ip` | integer pair | `3, 1` | | two ids | bodies |'//NL) > 0, &
               'reference table: an integer pair')
    call check(index(tab, NL//'| `sp` | string pair (at most 6 characters each) | `''top'', ''rim''` | | | '// &
               'groups |'//NL) > 0, 'reference table: a string pair')
    call check(index(render_group('g', v, 200), 'ip=3, 1, sp=''top'', ''rim'' /') > 0, &
               'render_group: an integer pair and a string pair')
    code = 2
    tab = reference_table(v)
    call check(index(tab, NL//'| `c` | choice | `''two''` | | `''one''`, `''two''` | |'//NL) > 0 .and. &
               index(tab, 'only:') == 0, 'reference table: the current value is the default; no forms, no notes')
  end block

  call test_summary()

contains

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    call report(ok, what)
  end subroutine check

  !> The contact pairs: the two-body form is the pair (1, 2); the pair form in any order of
  !! ids, with its overrides; each bad deck refused with its message (the solver's two-body
  !! limit only after the checks).
  subroutine test_pairs()
    type(deck_t) :: p
    type(contact_cfg_t) :: q
    character(len=200) :: o(2)
    character(len=100), parameter :: B1 = '&body id=1, y0=2.0, nx=2, ny=2 /', &
      B2 = '&body id=2, y0=1.0, nx=2, ny=2, left=''roller'' /', &
      B3 = '&body id=3, y0=0.0, nx=2, ny=2, bottom=''clamped'' /', &
      T1 = '&traction body=1, side=''top'', t0=0.0, -1.0e6 /', &
      P12 = '&contact bodies=1,2, groups=''bottom'',''top'' /', &
      P23 = '&contact bodies=2,3, groups=''bottom'',''top'' /'

    ! the default deck: no &contact, the pair of bodies 1 and 2 on their 'contact' sides
    call check(d%nbody == 2 .and. d%npair == 1 .and. .not. d%pairs_named, &
               'pairs: the default deck has two bodies in one pair, the two-body form')
    call check(all(d%pair(1)%bodies == [1, 2]) .and. all(d%pair(1)%body_group == ''), &
               'pairs: without &contact the pair is bodies 1, 2 on their contact sides')

    ! the two-body form with groups
    call write_file(trim(tmp)//'_two.nml', [character(len=120) :: &
      '&body id=1, y0=1.0, nx=2, ny=2, left=''clamped'' /', &
      '&body id=2, y0=0.0, nx=2, ny=2, bottom=''clamped'' /', T1, &
      '&contact body1_group=''bottom'', body2_group=''top'', slave=2, gap_radius=4.0 /'])
    call read_good(trim(tmp)//'_two.nml', none, p)
    call check(p%npair == 1 .and. all(p%pair(1)%bodies == [1, 2]) .and. &
               p%pair(1)%body_group(1) == 'bottom' .and. p%pair(1)%body_group(2) == 'top' .and. &
               p%pair(1)%slave == 2 .and. p%pair(1)%gap_radius == 4.0_wp .and. .not. p%pairs_named, &
               'pairs: the two-body form is the pair (1, 2) with its groups')
    call check(index(p%effective, '&contact body1_group=''bottom'', body2_group=''top''') > 0, &
               'pairs: the two-body form is rendered in the two-body form')
    call round_trip(p, 'two-body form')
    o(1) = '&contact body2_group=''top'', gap_radius=1.0 /'
    call read_good(trim(tmp)//'_two.nml', o(1:1), p)
    call check(p%pair(1)%gap_radius == 1.0_wp .and. p%pair(1)%slave == 2, &
               'pairs: an override in the two-body form changes the pair (1, 2)')
    o(1) = '&contact bodies=2,1, groups=''top'',''rim'', slave=1 /'
    call read_good(trim(tmp)//'_two.nml', o(1:1), p)
    call check(all(p%pair(1)%bodies == [1, 2]) .and. p%pair(1)%body_group(1) == 'rim' .and. &
               p%pair(1)%body_group(2) == 'top' .and. p%pair(1)%slave == 1 .and. .not. p%pairs_named, &
               'pairs: an override naming the pair (2, 1) of a two-body deck keeps body 1''s group first')
    call delete_file(trim(tmp)//'_two.nml')

    ! the pair form, bodies out of order and a pair given as (3, 2)
    call write_file(trim(tmp)//'_stack.nml', [character(len=120) :: B3, B1, B2, T1, P12, &
      '&contact bodies=3,2, groups=''top'',''bottom'', slave=2, gap_radius=2.5, gap_center=0.5 /'])
    call read_good(trim(tmp)//'_stack.nml', none, p)
    call check(p%nbody == 3 .and. p%npair == 2 .and. p%pairs_named, 'pairs: three bodies, two named pairs')
    call check(p%body(1)%y0 == 2.0_wp .and. p%body(3)%y0 == 0.0_wp .and. p%body(3)%id == 3 .and. &
               p%body(3)%bc(SIDE_BOTTOM) == BC_CLAMPED, 'pairs: bodies stored by id, whatever their order')
    call check(all(p%pair(1)%bodies == [1, 2]) .and. p%pair(1)%body_group(1) == 'bottom' .and. &
               p%pair(1)%body_group(2) == 'top' .and. p%pair(1)%slave == 0, 'pairs: pair 1 as given')
    call check(all(p%pair(2)%bodies == [3, 2]) .and. p%pair(2)%body_group(1) == 'top' .and. &
               p%pair(2)%body_group(2) == 'bottom' .and. p%pair(2)%slave == 2 .and. &
               p%pair(2)%gap_radius == 2.5_wp .and. p%pair(2)%gap_center == 0.5_wp, &
               'pairs: pair 2 keeps the order of its bodies, groups, slave and gap')
    q = pair_oriented(p%pair(2))
    call check(all(q%bodies == [2, 3]) .and. q%body_group(1) == 'bottom' .and. q%body_group(2) == 'top', &
               'pairs: pair_oriented swaps bodies and groups')
    call round_trip(p, 'pair form')
    o(1) = '&contact bodies=2,3, groups=''bottom'',''top'', slave=3 /'
    o(2) = '&body id=3, young=1e9 /'
    call read_good(trim(tmp)//'_stack.nml', o, p)
    call check(all(p%pair(2)%bodies == [2, 3]) .and. p%pair(2)%body_group(1) == 'bottom' .and. &
               p%pair(2)%slave == 3 .and. p%pair(2)%gap_radius == 2.5_wp .and. p%body(3)%young == 1.0e9_wp, &
               'pairs: an override names its pair by its bodies, in either order')
    o(1) = '&contact bodies=3,2, slave=3 /'
    call read_good(trim(tmp)//'_stack.nml', o(1:1), p)
    call check(all(p%pair(2)%bodies == [3, 2]) .and. p%pair(2)%body_group(1) == 'top' .and. &
               p%pair(2)%slave == 3, 'pairs: an override in the deck''s order keeps the groups')
    call delete_file(trim(tmp)//'_stack.nml')

    ! bad decks: each refused with its message (exit code 1)
    call refused('self', [character(len=120) :: B1, B2, B3, P12, &
      '&contact bodies=2,2, groups=''bottom'',''top'' /', T1], &
      ':5: in group &contact: bodies = 2,2 pairs body 2 with itself')
    call refused('unknown', [character(len=120) :: B1, B2, B3, P12, &
      '&contact bodies=2,4, groups=''bottom'',''top'' /', T1], &
      ':5: in group &contact: bodies = 2,4 names body 4, which does not exist')
    call refused('same_group', [character(len=120) :: B1, B2, B3, P12, &
      '&contact bodies=2,1, groups=''left'',''bottom'' /', P23, T1], &
      'the &contact at line 4 and the &contact at line 5 both name group ''bottom'' of body 1 with body 2')
    call refused('gap', [character(len=120) :: B1, B2, '&body id=4, nx=2, ny=2 /', P12, P23, T1], &
      ':3: in group &body: id = 4 is not a body id: the deck''s 3 bodies have ids 1 to 3')
    call refused('duplicate', [character(len=120) :: B1, B2, '&body id=2, nx=2, ny=2 /', P12, P23, T1], &
      ':3: in group &body: id = 2 is used twice (also by the &body at line 2)')
    call refused('no_pair', [character(len=120) :: B1, B2, B3, P12, T1], &
      'body 3 (&body at line 3) is in no contact pair')
    call refused('none', [character(len=120) :: B1, B2, B3, T1], 'the deck has 3 bodies and no &contact')
    call refused('slave', [character(len=120) :: B1, B2, B3, P12, &
      '&contact bodies=2,3, groups=''bottom'',''top'', slave=1 /', T1], &
      ':5: in group &contact: slave = 1 is not a body of the pair (bodies=2, 3)')
    call refused('mixed', [character(len=120) :: B1, B2, &
      '&contact body1_group=''bottom'', body2_group=''top'' /', P12, T1], &
      ':4: in group &contact: this group has the pair form')
    call refused('mixed_group', [character(len=120) :: B1, B2, &
      '&contact bodies=1,2, groups=''bottom'',''top'', body1_group=''bottom'' /', T1], &
      ':3: in group &contact: body1_group and body2_group belong to the two-body form')
    call refused('no_groups', [character(len=120) :: B1, B2, '&contact bodies=1,2 /', T1], &
      'names no group for body 1')
    call refused('no_bodies', [character(len=120) :: B1, B2, '&contact groups=''bottom'',''top'' /', T1], &
      ':3: in group &contact: no bodies')
    call refused('not_a_side', [character(len=120) :: B1, B2, &
      '&contact bodies=1,2, groups=''bottom'',''rim'' /', T1], &
      'the &contact at line 3 names group ''rim'' of body 2, a rectangle')
  end subroutine test_pairs

  !> read_deck on a good deck: a failure is a failed check (with its message).
  subroutine read_good(path, overrides, out)
    character(len=*), intent(in) :: path, overrides(:)
    type(deck_t), intent(out) :: out
    type(error_t) :: err
    call read_deck(path, overrides, out, err)
    if (err%failed()) call check(.false., 'read_deck '//path//' (refused: '//err%message//')')
  end subroutine read_good

  !> The deck of `lines` refused by read_deck: ERR_INPUT (exit code 1), the message starting
  !! with the deck's path (with `expect` right after it when `expect` starts with its line
  !! ':N:') and holding `expect`.
  subroutine refused(name, lines, expect)
    character(len=*), intent(in) :: name, lines(:), expect
    character(len=:), allocatable :: f, msg
    type(deck_t) :: p
    type(error_t) :: err
    logical :: ok
    f = trim(tmp)//'_bad_'//name//'.nml'
    call write_file(f, lines)
    call read_deck(f, none, p, err)
    msg = err%text()
    ok = err%category == ERR_INPUT .and. exit_code(err) == EXIT_INPUT .and. index(msg, f) == 1 .and. &
         index(msg, expect) > 0
    if (expect(1:1) == ':') ok = ok .and. index(msg, f//expect) == 1
    if (ok) then
      call check(.true., 'bad deck '''//name//''': ERR_INPUT and "'//expect//'"')
    else
      call check(.false., 'bad deck '''//name//''': ERR_INPUT and "'//expect//'" (category '// &
                 achar(48 + min(max(err%category, 0), 9))//': '//msg//')')
    end if
    call delete_file(f)
  end subroutine refused

  !> print_deck -> file -> read_deck must give identical values and identical text.
  subroutine round_trip(a, what)
    type(deck_t), intent(in) :: a
    character(len=*), intent(in) :: what
    type(deck_t) :: b
    integer :: u
    character(len=:), allocatable :: f, diff
    f = trim(tmp)//'_roundtrip.nml'
    open (newunit=u, file=f, status='replace', action='write')
    call print_deck(a, u)
    close (u)
    call read_good(f, none, b)
    call compare(a, b, diff)
    call check(len(diff) == 0, 'round trip of the '//what//': identical values'//diff)
    call check(after_first_line(a%effective) == after_first_line(b%effective), &
               'round trip of the '//what//': identical effective text')
    call delete_file(f)
  end subroutine round_trip

  function after_first_line(s) result(r)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: r
    r = s(index(s, achar(10)) + 1:)
  end function after_first_line

  subroutine compare(a, b, diff)
    type(deck_t), intent(in) :: a, b
    character(len=:), allocatable, intent(out) :: diff
    integer :: k, i
    diff = ''
    if (a%title /= b%title) diff = diff//' title'
    if (a%plane_strain .neqv. b%plane_strain) diff = diff//' plane'
    if (a%nbody /= b%nbody .or. a%npair /= b%npair .or. (a%pairs_named .neqv. b%pairs_named)) then
      diff = diff//' nbody-npair-form'
      return
    end if
    do k = 1, a%npair
      associate (x => a%pair(k), y => b%pair(k))
        if (any(x%bodies /= y%bodies) .or. any(x%body_group /= y%body_group) .or. x%slave /= y%slave &
            .or. x%gap_radius /= y%gap_radius .or. x%gap_center /= y%gap_center) diff = diff//' pair'
      end associate
    end do
    do k = 1, a%nbody
      associate (x => a%body(k), y => b%body(k))
        if (x%id /= y%id .or. x%nx /= y%nx .or. x%ny /= y%ny .or. x%element /= y%element) &
          diff = diff//' body-integers'
        if (x%x0 /= y%x0 .or. x%y0 /= y%y0 .or. x%width /= y%width .or. x%height /= y%height) &
          diff = diff//' body-geometry'
        if (x%young /= y%young .or. x%poisson /= y%poisson) diff = diff//' body-material'
        if (any(x%bc /= y%bc)) diff = diff//' body-bc'
        if (any(x%u_side /= y%u_side)) diff = diff//' body-u_side'
      end associate
    end do
    if (a%ntraction /= b%ntraction) then
      diff = diff//' ntraction'
    else
      do i = 1, a%ntraction
        if (a%traction(i)%body /= b%traction(i)%body .or. a%traction(i)%side /= b%traction(i)%side &
            .or. any(a%traction(i)%t0 /= b%traction(i)%t0) .or. any(a%traction(i)%t1 /= b%traction(i)%t1)) &
          diff = diff//' traction'
      end do
    end if
    associate (x => a%solver, y => b%solver)
      if (x%method /= y%method .or. x%robin_operator /= y%robin_operator .or. x%stop /= y%stop .or. &
          x%factor%factorization /= y%factor%factorization .or. x%factor%ordering /= y%factor%ordering .or. &
          x%acceleration /= y%acceleration) diff = diff//' solver-enumerations'
      if (x%alpha /= y%alpha .or. x%delta /= y%delta .or. x%tol /= y%tol .or. &
          x%inner_factor /= y%inner_factor .or. x%inner_rtol_min /= y%inner_rtol_min .or. &
          x%inner_rtol_max /= y%inner_rtol_max .or. x%monolithic_rtol /= y%monolithic_rtol) &
        diff = diff//' solver-reals'
      if (x%max_outer /= y%max_outer .or. x%inner_max_it /= y%inner_max_it) diff = diff//' solver-integers'
    end associate
    if (a%output%file /= b%output%file .or. a%output%checkpoint_every /= b%output%checkpoint_every &
        .or. a%output%progress_lines /= b%output%progress_lines) diff = diff//' output'
    if (len(diff) > 0) diff = ' (differ:'//diff//')'
  end subroutine compare

  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: u, ios
    open (newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close (u, status='delete')
  end subroutine delete_file

end program test_deck
