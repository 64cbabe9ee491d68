!> The input deck: namelist groups read into a `deck_t` (through `namelist_input`), validated
!! value by value and across fields, with clear messages on bad input, and rendered back as
!! namelist text.
!!
!! Groups: `&scene`, `&material` and `&region` (any number), `&body` (N of them, ids 1 to N),
!! `&traction`, `&body_force`,
!! `&displacement` and `&boundary` (any number, any order), `&contact` (the two-body form once, or one per
!! contact pair), `&solver`, `&output` (each at most once; all optional). Command-line
!! overrides are namelist fragments applied after the deck: `&body id=2, young=1e9 /`
!! changes body 2, `&contact bodies=2,3, slave=3 /` the pair of bodies 2 and 3,
!! `&traction ... /` adds a traction, other groups change the values given. Every bad input is
!! returned as an `error_t` (ERR_INPUT) whose message names the source (deck file and line,
!! or command-line override k), the group, the variable and the value, followed by the
!! offending line: the message names its source itself, so the driver adds no context.
!!
!! Each group's variables are declared once, in its table (`deck_tables`), which reads the
!! group, renders it back (`deck_render`) and documents it (`deck_reference`,
!! doc/deck-reference.md): a new setting is its field in `config`, one line in the table
!! (with its description, unit and range), and its range check (if it has one) in the
!! group's `apply_*` (`deck_checks`). This module reads the deck and its overrides in order.
module deck
  use errors, only: error_t, ERR_INPUT
  use strings, only: i2s, index_of
  use namelist_input, only: src_t, grp_t, load_file, text_source, parse_source, die_at, unknown_group
  use config, only: deck_t, ACCEL_AUTO, ACCEL_NONE, ACCEL_ANDERSON, STOP_AUTO, STOP_INCREMENT, STOP_RESIDUAL
  use deck_checks, only: state_t, start_state, apply_single, new_body, override_body, add_traction, add_body_force, &
                         resolve_dimension, &
                         add_boundary, apply_displacement, add_contact, add_material, add_region
  use deck_cross, only: check_cross, resolve_materials
  use deck_render, only: deck_text, print_deck, deck_reference
  implicit none (type, external)
  private

  public :: read_deck, deck_text, print_deck, deck_usage, deck_reference

  character(len=*), parameter :: NL = achar(10)

  !> Usage text for the main program (`--help`, and printed when it is called without a deck).
  character(len=*), parameter :: deck_usage = &
    'usage: robin_contact DECK.nml [OVERRIDE ...] [--restart FILE.ckpt.h5]'//NL// &
    '       robin_contact --help | --version | --deck-reference'//NL// &
    '       mpirun -np N robin_contact_mpi DECK.nml ...   (factorization=''mumps'')'//NL// &
    '  DECK.nml  input deck of Fortran namelist groups: &scene, two or more &body (ids 1 to'//NL// &
    '            N), any number of &material, &region, &traction, &body_force,'//NL// &
    '            &displacement and &boundary,'//NL// &
    '            &contact (one'//NL// &
    '            per contact pair; optional for two bodies on their ''contact'' sides),'//NL// &
    '            &solver, &output; /dev/stdin reads it from a pipe'//NL// &
    '  OVERRIDE  a namelist fragment applied after the deck, in order, e.g.'//NL// &
    "              '&solver delta=0.5 /'   '&body id=2, young=1e9 /'"//NL// &
    '              "&traction body=1, side=''top'', t0=0.0,-1.0e6 /"   (adds a traction)'//NL// &
    '  --restart FILE.ckpt.h5   continue the run of the same deck and overrides from its'//NL// &
    '            checkpoint (method=''robin''; &output checkpoint_every=N writes one)'//NL// &
    '  --help            print this text'//NL// &
    '  --version         print the program version'//NL// &
    '  --deck-reference  print the reference of every deck variable (Markdown)'//NL// &
    '  Exit codes: 0 converged, 1 bad input or usage, 2 not converged, 3 numerical or I/O'//NL// &
    '              failure, 4 interrupted (SIGTERM or SIGINT).'//NL// &
    '  Documentation: README.md; doc/deck-reference.md (the output of --deck-reference);'//NL// &
    '  inputs/default.nml (the paper''s scene, every group commented).'

  character(len=*), parameter :: GROUP_NAMES = &
    'scene body material region traction body_force displacement boundary contact solver output'

contains

  ! ============================================================================================
  ! Public API
  ! ============================================================================================

  !> Read the deck file `path`, then apply the command-line `overrides` in order, validate
  !! everything and fill `d` (with `d%effective`, the effective deck as namelist text).
  !! On any bad input `err` holds ERR_INPUT and the message, which starts with its source (the
  !! deck path and line, or 'command-line override k'), or says that the path itself is
  !! wrong (empty, too long); `d` is then incomplete.
  subroutine read_deck(path, overrides, d, err)
    character(len=*), intent(in) :: path          !< deck file path
    character(len=*), intent(in) :: overrides(:)  !< namelist fragments from the command line
    type(deck_t), intent(out) :: d                !< the effective deck
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(state_t) :: st
    type(src_t) :: src
    type(grp_t), allocatable :: gs(:)
    integer :: i, k, ig
    character(len=:), allocatable :: olabel

    if (len(path) > len(d%source)) then
      call err%set(ERR_INPUT, 'the deck path is '//i2s(len(path))// &
        ' characters long, longer than the system''s limit of '//i2s(len(d%source))//' (PATH_MAX)')
      return
    end if
    d%source = path
    if (len_trim(path) == 0) then
      call err%set(ERR_INPUT, 'no deck file given'//NL//deck_usage)
      return
    end if
    call load_file(path, src, err)
    if (err%failed()) return
    call parse_source(src, GROUP_NAMES, gs, err)
    if (err%failed()) return
    ! the &body groups, counted first: the ids are 1 to their number
    k = 0
    do i = 1, size(gs)
      if (gs(i)%name == 'body') k = k + 1
    end do
    call start_state(path, k, d, st)

    ! Pass 1: everything but the loads, which refer to the bodies.
    do i = 1, size(gs)
      ig = index_of(GROUP_NAMES, gs(i)%name)
      if (ig == 0) then
        call unknown_group(gs(i), src, GROUP_NAMES, err)
        return
      end if
      select case (gs(i)%name)
      case ('traction', 'body_force', 'displacement', 'boundary')
        cycle
      case ('body')
        call new_body(gs(i), src, d, st, err)
        if (err%failed()) return
      case ('material')
        call add_material(gs(i), src, d, 'line '//i2s(gs(i)%line), .false., err)
        if (err%failed()) return
      case ('region')
        call add_region(gs(i), src, d, 'line '//i2s(gs(i)%line), .false., err)
        if (err%failed()) return
      case ('contact')
        call add_contact(gs(i), src, d, st, err)
        if (err%failed()) return
      case default
        if (st%once_line(ig) > 0) then
          call die_at(src, gs(i)%line, 'group &'//gs(i)%name// &
            ' appears twice in the deck (first at line '//i2s(st%once_line(ig))// &
            '); give each of its variables in one group', err)
          return
        end if
        st%once_line(ig) = gs(i)%line
        call apply_single(gs(i), src, d, err)
        if (err%failed()) return
      end select
    end do
    if (st%nbody == 0) then
      call err%set(ERR_INPUT, path//': the deck has no &body group; it needs '// &
        'at least two, &body id=1 ... / and &body id=2 ... /')
      return
    end if
    if (st%nbody == 1) then
      call err%set(ERR_INPUT, path//': the deck has only one &body group (id=1, '// &
        'line '//i2s(st%body_line(1))//'); it needs at least two, in contact')
      return
    end if
    call resolve_dimension(path, d, st, err)
    if (err%failed()) return
    if (d%npair == 0 .and. d%nbody == 2) then   ! no &contact: bodies 1 and 2 on their 'contact' sides
      d%npair = 1
      st%pair_at(1)%s = 'two-body contact'
    end if

    ! Pass 2: loads, in deck order.
    do i = 1, size(gs)
      if (gs(i)%name == 'traction') then
        call add_traction(gs(i), src, d, st, 'line '//i2s(gs(i)%line), err)
        if (err%failed()) return
      end if
      if (gs(i)%name == 'body_force') then
        call add_body_force(gs(i), src, d, 'line '//i2s(gs(i)%line), err)
        if (err%failed()) return
      end if
      if (gs(i)%name == 'displacement') then
        call apply_displacement(gs(i), src, d, st, err)
        if (err%failed()) return
      end if
      if (gs(i)%name == 'boundary') then
        call add_boundary(gs(i), src, d, 'line '//i2s(gs(i)%line), err)
        if (err%failed()) return
      end if
    end do

    ! Command-line overrides, in order.
    do k = 1, size(overrides)
      olabel = 'command-line override '//i2s(k)
      call text_source(overrides(k), olabel, src)
      call parse_source(src, GROUP_NAMES, gs, err)
      if (err%failed()) return
      if (size(gs) == 0) then
        call err%set(ERR_INPUT, olabel//': no namelist group in "'// &
          trim(overrides(k))//'"; an override looks like ''&solver delta=0.5 /''')
        return
      end if
      do i = 1, size(gs)
        ig = index_of(GROUP_NAMES, gs(i)%name)
        if (ig == 0) then
          call unknown_group(gs(i), src, GROUP_NAMES, err)
          return
        end if
        select case (gs(i)%name)
        case ('body')
          call override_body(gs(i), src, d, st, err)
          if (err%failed()) return
        case ('material')
          call add_material(gs(i), src, d, olabel, .true., err)
          if (err%failed()) return
        case ('region')
          call add_region(gs(i), src, d, olabel, .true., err)
          if (err%failed()) return
        case ('contact')
          call add_contact(gs(i), src, d, st, err)
          if (err%failed()) return
        case ('traction')
          call add_traction(gs(i), src, d, st, olabel, err)
          if (err%failed()) return
        case ('body_force')
          call add_body_force(gs(i), src, d, olabel, err)
          if (err%failed()) return
        case ('displacement')
          call apply_displacement(gs(i), src, d, st, err)
          if (err%failed()) return
        case ('boundary')
          call add_boundary(gs(i), src, d, olabel, err)
          if (err%failed()) return
        case default
          call apply_single(gs(i), src, d, err)
          if (err%failed()) return
        end select
      end do
    end do

    if (len_trim(d%output%file) == 0) d%output%file = default_output(path)
    call check_cross(d, st, err)
    if (err%failed()) return
    call resolve_materials(d, st, err)
    if (err%failed()) return
    ! the defaults that depend on the scene: two bodies in one pair keep the paper's stop and no
    ! acceleration; a chain of bodies passes its forces one contact per outer iteration
    if (d%solver%acceleration == ACCEL_AUTO) d%solver%acceleration = merge(ACCEL_NONE, ACCEL_ANDERSON, d%npair <= 1)
    if (d%solver%stop == STOP_AUTO) d%solver%stop = merge(STOP_INCREMENT, STOP_RESIDUAL, d%npair <= 1)
    call deck_text(d, d%effective)
  end subroutine read_deck

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

end module deck
