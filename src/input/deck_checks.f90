!> The checks of the deck's groups as they are read: each group read into its settings
!! through its table (`deck_tables`), its values checked (`apply_*`, `new_body`,
!! `add_traction`, ...); the checks across groups, once the deck and its overrides are read,
!! are in `deck_cross`.
!! Every bad input is returned as an `error_t` (ERR_INPUT) whose message names the source,
!! group, variable and value; the procedures stop at the first.
module deck_checks
  use kinds, only: wp
  use space, only: NDIM, set_dimension
  use errors, only: error_t, ERR_INPUT
  use strings, only: i2s, roundtrip, sci, quote, quoted_list, word
  use namelist_vars, only: str_t, vars_t
  use namelist_input, only: src_t, grp_t, read_group, find_asg, find_int, die_at, bad_value

  use config, only: MAX_SIDES, MODULUS_MIN, MODULUS_MAX, pair_oriented, deck_t, body_cfg_t, body_force_cfg_t, material_cfg_t, region_cfg_t, &
                    MAT_ISOTROPIC, MAT_ORTHOTROPIC, MAT_ANISOTROPIC, MAT_KIND_NAMES, UNSET, traction_cfg_t, boundary_cfg_t, contact_cfg_t, solver_cfg_t, output_cfg_t, &
                    side_names, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_CONTACT, BC_DISPLACEMENT, bc_names, &
                    ROBIN_CONSTANT, SIDE_CHOICES, UNITS_CHOICES, UNITS_SI, UNITS_MM, units_cfg_t, &
                    FRICTION_TRESCA, FRICTION_COULOMB, OVERLAP_INTERFERENCE, MAX_STAGES, MAX_STEPS, STEPS_UNSET
  use deck_tables, only: scene_in_t, load_in_t, ALL_FORMS, TWO_BODY_FORM, PAIR_FORM, scene_vars, body_vars, body_force_vars, &
                         traction_vars, boundary_vars, displacement_vars, contact_vars, solver_vars, output_vars, &
                         material_vars, region_vars
  implicit none (type, external)
  private

  real(wp), parameter :: MU_MAX = 1.0e4_wp     !< the largest Coulomb coefficient accepted
  real(wp), parameter :: SLIP_MAX = 1.0e20_wp  !< the largest Tresca bound accepted [stress]

  public :: state_t, start_state, apply_single, new_body, override_body, add_traction, add_boundary, add_body_force, &
            apply_displacement, add_contact, add_material, add_region, resolve_dimension


  !> Where things came from, for cross-field messages.
  type :: state_t
    character(len=:), allocatable :: path
    integer :: nbody = 0                        ! &body groups read so far
    integer, allocatable :: body_line(:)        ! line of each &body in the deck file, per id
    type(str_t), allocatable :: body_at(:)      ! '&body at line N' (and its overrides), per id
    type(str_t), allocatable :: trac_at(:)      ! per traction
    integer, allocatable :: disp_line(:, :)     ! deck line of the &displacement per side, body
    logical, allocatable :: disp_given(:, :)    ! a &displacement gives the side's vector
    integer :: once_line(16) = 0                ! deck line of each singleton group (by its place in the group names)
    integer :: contact_form = 0                 ! the deck's &contact form (TWO_BODY_FORM, PAIR_FORM; 0: none)
    integer :: contact_line = 0                 ! line of the deck's first &contact
    type(str_t), allocatable :: pair_at(:)      ! '&contact at line N' (and its overrides), per pair
    !> per body: its first variable of a box ('z0', 'depth', 'nz', 'front', 'back') given, as
    !! 'line N: name = value', '' if none
    type(str_t), allocatable :: box_var(:)
  end type state_t

  !> Room for item `n` of a list the deck adds to group by group (pairs, tractions, body forces,
  !! materials, regions, boundaries, and their origins): allocated at 4 on first use, doubled
  !! when full, so that a deck of many groups is read in linear time. One specific per item
  !! type, each the same three steps (`capacity` is the rule).
  interface grow
    module procedure grow_pairs, grow_strs, grow_tractions, grow_body_forces, grow_materials, grow_regions, &
      grow_boundaries
  end interface grow

contains

  !> A group that appears at most once (&scene, &solver, &output): read into its
  !! settings through its table, then its values checked.
  subroutine apply_single(g, src, d, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), target, intent(inout) :: d
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(scene_in_t), target :: sc
    type(vars_t) :: v
    integer :: k, dim0
    select case (g%name)
    case ('scene')
      sc%plane = merge(3, merge(1, 2, d%plane_strain), d%axisymmetric)
      dim0 = d%dimension       ! 0 in the deck (resolved after its bodies), 2 or 3 in an override
      call scene_vars(d, sc, v)
    case ('solver')
      call solver_vars(d%solver, v)
      ! a new list replaces the old one whole (an override load_steps=4 means 4 per stage)
      k = find_asg(g, 'load_steps')
      if (k > 0) then
        if (g%a(k)%sub == 0) d%solver%load_steps = STEPS_UNSET
      end if
    case ('output')
      call output_vars(d%output, v)
    end select
    call read_group(g, src, v, err)
    if (err%failed()) return
    select case (g%name)
    case ('scene')
      d%plane_strain = (sc%plane /= 2)
      d%axisymmetric = (sc%plane == 3)
      if (find_asg(g, 'dimension') > 0) then
        if (d%dimension /= 2 .and. d%dimension /= 3) then
          call bad_value(g, src, 'dimension', i2s(d%dimension), &
            'must be 2 (plane or axisymmetric bodies) or 3 (solid bodies)', err)
          return
        end if
        if (dim0 /= 0 .and. d%dimension /= dim0) then
          call bad_value(g, src, 'dimension', i2s(d%dimension), &
            'cannot be changed by a command-line override (the deck is '//i2s(dim0)//'D: its loads were read '// &
            'so); give it in the deck''s &scene', err)
          return
        end if
      end if
      call check_units(g, src, d%units, err)
      if (err%failed()) return
    case ('solver')
      call check_solver(g, src, d%solver, err)
      if (err%failed()) return
    case ('output')
      call check_output(g, src, d%output, err)
      if (err%failed()) return
    end select
  end subroutine apply_single

  !> The deck `d` of `nbody` bodies (the &body groups of the file, counted before they are
  !! read: the ids are then 1 to nbody) before its groups are read, and the state `st`.
  subroutine start_state(path, nbody, d, st)
    character(len=*), intent(in) :: path   !< the deck file
    integer, intent(in) :: nbody           !< its number of &body groups
    type(deck_t), intent(inout) :: d
    type(state_t), intent(out) :: st
    integer :: b
    st%path = path
    allocate (d%body(nbody), d%pair(4), d%traction(4), d%boundary(4), st%trac_at(4), st%pair_at(4))
    allocate (st%body_line(nbody), st%body_at(nbody), st%disp_line(MAX_SIDES, nbody), st%disp_given(MAX_SIDES, nbody))
    allocate (st%box_var(nbody))
    st%body_line = 0
    st%disp_line = 0
    st%disp_given = .false.
    do b = 1, nbody
      d%body(b)%id = 0
      st%body_at(b)%s = ''
      st%box_var(b)%s = ''
    end do
    d%nbody = nbody
    d%npair = 0
    d%ntraction = 0
    d%nboundary = 0
  end subroutine start_state

  !> The ids of the deck's bodies, in words.
  function ids_text(n) result(s)
    integer, intent(in) :: n
    character(len=:), allocatable :: s
    if (n == 2) then
      s = 'ids 1 and 2'
    else
      s = 'ids 1 to '//i2s(n)
    end if
  end function ids_text

  !> A &contact group. The two-body form (body1_group, body2_group, or neither) is the pair
  !! of bodies 1 and 2, at most once; the pair form (bodies=A,B, groups='GA','GB') adds a
  !! pair, any number of times. A deck uses one form. An override changes a pair: the
  !! two-body one, or the one its bodies= names.
  subroutine add_contact(g, src, d, st, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(contact_cfg_t), target :: c
    type(vars_t) :: v
    integer :: form, n
    logical :: named, legacy

    named = find_asg(g, 'bodies') > 0 .or. find_asg(g, 'groups') > 0
    legacy = find_asg(g, 'body1_group') > 0 .or. find_asg(g, 'body2_group') > 0
    if (named .and. legacy) then
      call die_at(src, g%line, 'in group &contact: body1_group and '// &
        'body2_group belong to the two-body form, bodies and groups to the pair form; give one form', err)
      return
    end if
    form = merge(PAIR_FORM, TWO_BODY_FORM, named)
    if (.not. src%is_file) then
      call override_contact(g, src, d, st, form, err)
      if (err%failed()) return
      return
    end if
    if (st%contact_form /= 0 .and. st%contact_form /= form) then
      call die_at(src, g%line, 'in group '// &
        '&contact: this group has '//form_words(form)//', but the &contact at line '//i2s(st%contact_line)// &
        ' has '//form_words(st%contact_form)//'; a deck uses one form: the two-body form '// &
        '(&contact body1_group=..., body2_group=... /, bodies 1 and 2) or a &contact bodies=A,B, '// &
        'groups=''GA'',''GB'' / per pair', err)
      return
    end if
    if (st%contact_form == 0) st%contact_line = g%line
    st%contact_form = form
    if (form == TWO_BODY_FORM) then
      if (d%npair > 0) then
        call die_at(src, g%line, 'group &contact appears twice in the deck (first '// &
          'at line '//i2s(st%contact_line)//'); give each of its variables in one group', err)
        return
      end if
      c%bodies = [1, 2]
    else
      c%bodies = 0
    end if
    call contact_vars(c, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call check_contact(g, src, c, form, d%nbody, err)
    if (err%failed()) return
    n = d%npair + 1
    call grow(d%pair, n)
    call grow(st%pair_at, n)
    d%npair = n
    d%pair(n) = c
    d%pairs_named = form == PAIR_FORM
    st%pair_at(n)%s = '&contact at line '//i2s(g%line)
  end subroutine add_contact

  !> A &contact on the command line: the pair form changes the pair of the bodies it names
  !! (in the order it gives them), and where the deck has several pairs of those bodies the
  !! one whose groups it gives (groups= then picks, never changes; without it the override
  !! is refused, naming the candidates); the two-body form the pair of bodies 1 and 2 of a
  !! two-body deck.
  subroutine override_contact(g, src, d, st, form, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    integer, intent(in) :: form
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(contact_cfg_t), target :: c, probe
    type(vars_t) :: v
    integer :: k, p, nmatch
    character(len=:), allocatable :: cands

    if (form == TWO_BODY_FORM) then
      if (d%pairs_named) then
        call die_at(src, g%line, 'in group &contact: the deck names its pairs '// &
          '(&contact bodies=A,B at line '//i2s(st%contact_line)//'); an override of &contact names '// &
          'the pair it changes, e.g. ''&contact bodies=1,2, gap_radius=0.5 /''', err)
        return
      end if
      if (d%npair == 0) then
        call die_at(src, g%line, 'in group &contact: the deck has no pair of '// &
          'bodies 1 and 2 to change', err)
        return
      end if
      p = 1
      c = d%pair(1)
    else
      probe%bodies = 0
      call contact_vars(probe, v, ALL_FORMS)
      call read_group(g, src, v, err)
      if (err%failed()) return
      if (find_asg(g, 'bodies') == 0) then
        call die_at(src, g%line, 'in group &contact: an override '// &
          'in the pair form names the pair it changes: bodies=A,B', err)
        return
      end if
      ! the pairs of those bodies; several: the override's groups say which
      p = 0
      nmatch = 0
      cands = ''
      do k = 1, d%npair
        if (.not. (all(d%pair(k)%bodies == probe%bodies) .or. all(d%pair(k)%bodies == probe%bodies(2:1:-1)))) cycle
        nmatch = nmatch + 1
        if (p == 0) p = k
        cands = cands//merge(', ', '  ', nmatch > 1)//groups_words(d%pair(k), probe%bodies)//' ('// &
                st%pair_at(k)%s//')'
      end do
      if (p == 0) then
        call bad_value(g, src, 'bodies', i2s(probe%bodies(1))//', '//i2s(probe%bodies(2)), &
          'is no pair of the deck; an override changes a pair the deck gives', err)
        return
      end if
      if (nmatch > 1) then
        if (find_asg(g, 'groups') == 0) then
          call bad_value(g, src, 'bodies', '', 'names '//i2s(nmatch)// &
            ' pairs of the deck: '//trim(adjustl(cands))//'; say which with its groups, e.g. ''&contact bodies='// &
            i2s(probe%bodies(1))//','//i2s(probe%bodies(2))//', '//groups_words(d%pair(p), probe%bodies)//', ... /''', err)
          return
        end if
        p = 0
        do k = 1, d%npair
          if ((all(d%pair(k)%bodies == probe%bodies) .and. all(d%pair(k)%body_group == probe%body_group)) .or. &
              (all(d%pair(k)%bodies == probe%bodies(2:1:-1)) .and. &
               all(d%pair(k)%body_group == probe%body_group(2:1:-1)))) then
            p = k
            exit
          end if
        end do
        if (p == 0) then
          call bad_value(g, src, 'groups', '', 'is none of the '//i2s(nmatch)//' pairs of bodies '// &
            i2s(probe%bodies(1))//' and '//i2s(probe%bodies(2))//': '//trim(adjustl(cands))// &
            '; with several pairs of two bodies, groups= picks one of them', err)
          return
        end if
      end if
      c = d%pair(p)
      if (any(c%bodies /= probe%bodies)) then   ! given in the other order: the groups follow
        c%bodies = probe%bodies
        c%body_group = c%body_group(2:1:-1)
      end if
    end if
    call contact_vars(c, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call check_contact(g, src, c, merge(PAIR_FORM, TWO_BODY_FORM, d%pairs_named), d%nbody, err)
    if (err%failed()) return
    if (.not. d%pairs_named) c = pair_oriented(c)   ! the two-body form: body 1's group first
    d%pair(p) = c
    st%pair_at(p)%s = st%pair_at(p)%s//', changed by '//src%label
  end subroutine override_contact

  !> groups='GA','GB' of pair c in the order of `bodies` (the pair's bodies in either order).
  function groups_words(c, bodies) result(s)
    type(contact_cfg_t), intent(in) :: c
    integer, intent(in) :: bodies(2)
    character(len=:), allocatable :: s
    integer :: j1, j2
    j1 = merge(1, 2, c%bodies(1) == bodies(1))
    j2 = 3 - j1
    s = 'groups='''//trim(c%body_group(j1))//''','''//trim(c%body_group(j2))//''''
  end function groups_words

  function form_words(form) result(s)
    integer, intent(in) :: form
    character(len=:), allocatable :: s
    if (form == PAIR_FORM) then
      s = 'the pair form (bodies=A,B, groups=...)'
    else
      s = 'the two-body form (body1_group, body2_group, or neither)'
    end if
  end function form_words

  !> The unit names of a named system are fixed (given ones must agree); 'custom' needs all three.
  subroutine check_units(g, src, u, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(units_cfg_t), intent(inout) :: u
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    character(len=16) :: names(3)
    character(len=*), parameter :: vars(3) = ['length_unit', 'force_unit ', 'stress_unit']
    integer :: k
    select case (u%system)
    case (UNITS_SI)
      names = [character(len=16) :: 'm', 'N', 'Pa']
    case (UNITS_MM)
      names = [character(len=16) :: 'mm', 'N', 'MPa']
    case default
      do k = 1, 3
        if (len_trim(unit_name(u, k)) == 0) then
          call bad_value(g, src, trim(vars(k)), "''", &
            'is empty: with units=''custom'' give length_unit, force_unit and stress_unit', err)
          return
        end if
      end do
      return
    end select
    do k = 1, 3
      if (find_asg(g, trim(vars(k))) > 0 .and. unit_name(u, k) /= names(k)) then
        call bad_value(g, src, &
          trim(vars(k)), "'"//trim(unit_name(u, k))//"'", 'does not belong to units='''// &
          word(UNITS_CHOICES, u%system)//''' (whose '//trim(vars(k))//' is '''//trim(names(k))// &
          '''); use units=''custom'' to name your own', err)
        return
      end if
    end do
    u%length = names(1)
    u%force = names(2)
    u%stress = names(3)
  end subroutine check_units

  function unit_name(u, k) result(s)
    type(units_cfg_t), intent(in) :: u
    integer, intent(in) :: k
    character(len=16) :: s
    select case (k)
    case (1)
      s = u%length
    case (2)
      s = u%force
    case default
      s = u%stress
    end select
  end function unit_name

  !> The values of one pair: the gap; in the pair form its bodies (two different ids of the
  !! deck), its groups (both given) and a slave of the pair.
  subroutine check_contact(g, src, c, form, nbody, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(contact_cfg_t), intent(inout) :: c
    integer, intent(in) :: form, nbody
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k
    character(len=:), allocatable :: shown
    if (c%gap_radius < 0.0_wp) then
      call bad_value(g, src, 'gap_radius', roundtrip(c%gap_radius), &
        'must be >= 0 (0: no initial gap; R > 0: g0(x) = (x - gap_center)^2/(2R))', err)
      return
    end if
    if (c%mu < 0.0_wp .or. c%mu > MU_MAX) then
      call bad_value(g, src, 'mu', roundtrip(c%mu), 'must be >= 0 and <= 1e4 '// &
        '(the Coulomb friction coefficient: no pair of materials has more than about 10; a pair that must not slip '// &
        'sticks with any mu its load needs, and a larger one only spoils the conditioning)', err)
      return
    end if
    if (c%slip_bound < 0.0_wp .or. c%slip_bound > SLIP_MAX) then
      call bad_value(g, src, 'slip_bound', roundtrip(c%slip_bound), &
        'must be >= 0 and <= 1e20 (Tresca''s bound of the shear traction, in the deck''s stress unit)', err)
      return
    end if
    if (c%mu /= 0.0_wp .and. c%friction /= FRICTION_COULOMB) then
      call bad_value(g, src, 'mu', roundtrip(c%mu), &
        'is the Coulomb coefficient: give it with friction=''coulomb''', err)
      return
    end if
    if (c%slip_bound /= 0.0_wp .and. c%friction /= FRICTION_TRESCA) then
      call bad_value(g, src, 'slip_bound', &
        roundtrip(c%slip_bound), 'is Tresca''s bound: give it with friction=''tresca''', err)
      return
    end if
    if (c%interference_stage < 0 .or. c%interference_stage > MAX_STAGES) then
      call bad_value(g, src, &
        'interference_stage', i2s(c%interference_stage), 'must be >= 0 and <= '//i2s(MAX_STAGES)// &
        ' (0: the whole interference at once; s: ramped over stage s''s load steps)', err)
      return
    end if
    if (c%interference_stage /= 0 .and. c%overlap /= OVERLAP_INTERFERENCE) then
      call bad_value(g, src, &
        'interference_stage', i2s(c%interference_stage), 'ramps an interference fit: give it with '// &
        'overlap=''interference''', err)
      return
    end if
    if (form == TWO_BODY_FORM) then
      if (c%slave < 0 .or. c%slave > 2) then
        call bad_value(g, src, 'slave', i2s(c%slave), &
          'must be 1 or 2 (the body whose contact surface carries the multipliers), or 0 for the finer one', err)
        return
      end if
      return
    end if
    shown = i2s(c%bodies(1))//', '//i2s(c%bodies(2))
    if (find_asg(g, 'bodies') == 0) then
      call die_at(src, g%line, 'in group &contact: '// &
        'no bodies; a pair names its two bodies and their groups: bodies=A,B, groups=''GA'',''GB''', err)
      return
    end if
    do k = 1, 2
      if (c%bodies(k) < 1 .or. c%bodies(k) > nbody) then
        call bad_value(g, src, 'bodies', shown, &
          'names body '//i2s(c%bodies(k))//', which does not exist: the deck''s '//i2s(nbody)// &
          ' bodies have '//ids_text(nbody), err)
        return
      end if
    end do
    if (c%bodies(1) == c%bodies(2)) then
      call bad_value(g, src, 'bodies', shown, 'pairs body '// &
        i2s(c%bodies(1))//' with itself; a contact pair is two different bodies', err)
      return
    end if
    do k = 1, 2
      if (len_trim(c%body_group(k)) == 0) then
        call bad_value(g, src, 'groups', quote(trim(c%body_group(1)))// &
          ', '//quote(trim(c%body_group(2))), 'names no group for body '//i2s(c%bodies(k))// &
          '; give the contact surface of each body, in the order of bodies: groups=''GA'',''GB'' (a '// &
          'rectangle''s sides are the groups ''left'', ''right'', ''bottom'', ''top'')', err)
        return
      end if
    end do
    if (c%slave /= 0 .and. all(c%bodies /= c%slave)) then
      call bad_value(g, src, 'slave', i2s(c%slave), &
        'is not a body of the pair (bodies='//shown//'): give '//i2s(c%bodies(1))//' or '// &
        i2s(c%bodies(2))//', or 0 for the finer surface', err)
    end if
  end subroutine check_contact

  subroutine check_solver(g, src, s, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(solver_cfg_t), intent(inout) :: s
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    if (s%alpha < 0.0_wp) then
      call bad_value(g, src, 'alpha', roundtrip(s%alpha), 'must be >= 0', err)
      return
    end if
    if (s%robin_operator == ROBIN_CONSTANT .and. .not. s%alpha > 0.0_wp) then
      call bad_value(g, src, &
        'alpha', roundtrip(s%alpha), 'must be > 0 when robin_operator=''constant''', err)
      return
    end if
    if (.not. (s%delta > 0.0_wp .and. s%delta <= 1.0_wp)) then
      call bad_value(g, src, 'delta', &
        roundtrip(s%delta), 'is out of range: the relaxation must satisfy 0 < delta <= 1', err)
      return
    end if
    if (.not. s%tol > 0.0_wp) then
      call bad_value(g, src, 'tol', roundtrip(s%tol), 'must be > 0', err)
      return
    end if
    if (s%max_outer < 1) then
      call bad_value(g, src, 'max_outer', i2s(s%max_outer), 'must be >= 1', err)
      return
    end if
    if (.not. s%inner_factor > 0.0_wp) then
      call bad_value(g, src, 'inner_factor', roundtrip(s%inner_factor), &
        'must be > 0', err)
      return
    end if
    if (.not. (s%inner_rtol_min > 0.0_wp .and. s%inner_rtol_min < 1.0_wp)) then
      call bad_value(g, src, &
        'inner_rtol_min', roundtrip(s%inner_rtol_min), 'must satisfy 0 < inner_rtol_min < 1', err)
      return
    end if
    if (.not. (s%inner_rtol_max > 0.0_wp .and. s%inner_rtol_max < 1.0_wp)) then
      call bad_value(g, src, &
        'inner_rtol_max', roundtrip(s%inner_rtol_max), 'must satisfy 0 < inner_rtol_max < 1', err)
      return
    end if
    if (s%inner_rtol_max < s%inner_rtol_min) then
      call bad_value(g, src, 'inner_rtol_max', &
        roundtrip(s%inner_rtol_max), 'must be >= inner_rtol_min = '//roundtrip(s%inner_rtol_min), err)
      return
    end if
    if (s%inner_max_it < 1) then
      call bad_value(g, src, 'inner_max_it', i2s(s%inner_max_it), 'must be >= 1', err)
      return
    end if
    if (.not. (s%monolithic_rtol > 0.0_wp .and. s%monolithic_rtol < 1.0_wp)) then
      call bad_value(g, src, &
        'monolithic_rtol', roundtrip(s%monolithic_rtol), 'must satisfy 0 < monolithic_rtol < 1', err)
      return
    end if
    if (any(s%load_steps < 1 .and. s%load_steps /= STEPS_UNSET)) then
      call bad_value(g, src, 'load_steps', &
        i2s(minval(s%load_steps, mask=s%load_steps /= STEPS_UNSET)), 'must be >= 1 (steps per stage)', err)
      return
    end if
    ! every step's result is kept for the result file: a bound well above any ramp's need
    if (any(s%load_steps > MAX_STEPS)) then
      call bad_value(g, src, 'load_steps', i2s(maxval(s%load_steps)), &
        'is too many: at most '//i2s(MAX_STEPS)//' steps per stage', err)
      return
    end if
    if (s%load_steps(1) == STEPS_UNSET .or. any(s%load_steps(2:) /= STEPS_UNSET .and. &
        s%load_steps(1:MAX_STAGES - 1) == STEPS_UNSET)) call bad_value(g, src, 'load_steps', '(with gaps)', &
      'must be given without gaps: one value, or one per stage from stage 1', err)
  end subroutine check_solver

  subroutine check_output(g, src, o, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(output_cfg_t), intent(inout) :: o
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    o%file = adjustl(o%file)
    if (o%checkpoint_every < 0) then
      call bad_value(g, src, 'checkpoint_every', i2s(o%checkpoint_every), &
        'must be >= 0 (0: no checkpoints)', err)
      return
    end if
    if (o%progress_lines < 0) then
      call bad_value(g, src, 'progress_lines', i2s(o%progress_lines), &
        'must be >= 0', err)
    end if
  end subroutine check_output

  !> A &body in the deck file: a new body.
  subroutine new_body(g, src, d, st, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: id
    type(body_cfg_t) :: fresh

    call body_id(g, src, 'no id; give id=1 to id=N, N the number of &body groups', d%nbody, id, err)
    if (err%failed()) return
    if (d%body(id)%id /= 0) then
      call bad_value(g, src, 'id', i2s(id), &
        'is used twice (also by the &body at line '//i2s(st%body_line(id))// &
        '); the deck''s '//i2s(d%nbody)//' bodies must have '//ids_text(d%nbody)//', each once', err)
      return
    end if
    fresh%id = id
    call apply_body(g, src, fresh, id, d, st, err)
    if (err%failed()) return
    st%nbody = st%nbody + 1
    st%body_line(id) = g%line
    st%body_at(id)%s = '&body at line '//i2s(g%line)
  end subroutine new_body

  !> A &body on the command line: changes the existing body with that id.
  subroutine override_body(g, src, d, st, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: id
    type(body_cfg_t) :: copy

    call body_id(g, src, 'an override of &body must name the body it changes with id=1 or id=2, '// &
                 'e.g. ''&body id=2, young=1e9 /''', d%nbody, id, err)
    if (err%failed()) return
    copy = d%body(id)
    call apply_body(g, src, copy, id, d, st, err)
    if (err%failed()) return
    st%body_at(id)%s = st%body_at(id)%s//', changed by '//src%label
  end subroutine override_body

  !> The id= of a &body: given (else the message `missing`), and 1 to nbody.
  subroutine body_id(g, src, missing, nbody, id, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    character(len=*), intent(in) :: missing
    integer, intent(in) :: nbody
    integer, intent(out) :: id
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    logical :: found
    call find_int(g, 'id', id, found)
    if (.not. found) then
      call die_at(src, g%line, 'in group &body: '//missing, err)
      return
    end if
    if (id < 1 .or. id > nbody) then
      call bad_value(g, src, 'id', i2s(id), 'is not a body id: the '// &
        'deck''s '//i2s(nbody)//' bodies have '//ids_text(nbody)//' (each once, without gaps)', err)
    end if
  end subroutine body_id

  !> Read a &body group into a copy of `b0` (its current values) and store it as body `id`
  !! of `d`; a side no longer declared 'displacement' drops its &displacement.
  subroutine apply_body(g, src, b0, id, d, st, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(body_cfg_t), intent(in) :: b0
    integer, intent(in) :: id
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(body_cfg_t), target :: c
    type(vars_t) :: v
    integer :: s, k

    c = b0
    call body_vars(c, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    if (len_trim(c%mesh) > 0 .and. find_asg(g, 'mesh') > 0) then
      call mesh_body(g, src, c, st%path, err)
      if (err%failed()) return
    end if
    if (.not. c%width > 0.0_wp) then
      call bad_value(g, src, 'width', roundtrip(c%width), 'must be > 0', err)
      return
    end if
    if (.not. c%height > 0.0_wp) then
      call bad_value(g, src, 'height', roundtrip(c%height), 'must be > 0', err)
      return
    end if
    if (c%nx < 1) then
      call bad_value(g, src, 'nx', i2s(c%nx), 'must be >= 1 (cells along x)', err)
      return
    end if
    if (c%ny < 1) then
      call bad_value(g, src, 'ny', i2s(c%ny), 'must be >= 1 (cells along y)', err)
      return
    end if
    if (.not. c%young > 0.0_wp) then
      call bad_value(g, src, 'young', roundtrip(c%young), &
        'must be > 0 (Young''s modulus)', err)
      return
    end if
    call check_modulus(g, src, 'young', c%young, err)
    if (err%failed()) return
    if (c%poisson >= 0.5_wp) then
      call bad_value(g, src, 'poisson', roundtrip(c%poisson), 'is out of range: '// &
        'it must satisfy -1 < poisson < 0.5; poisson >= 0.5 (an incompressible material) is '// &
        'rejected: this displacement formulation cannot model it', err)
      return
    end if
    if (c%poisson <= -1.0_wp) then
      call bad_value(g, src, 'poisson', roundtrip(c%poisson), 'is out of range: '// &
        'it must satisfy -1 < poisson < 0.5', err)
      return
    end if
    if (.not. c%density >= 0.0_wp) then
      call bad_value(g, src, 'density', roundtrip(c%density), &
        'must be >= 0 (mass per volume)', err)
      return
    end if
    if (find_asg(g, 'material') > 0 .and. len_trim(c%material) > 0) then
      do s = 1, 3
        if (find_asg(g, trim(word('young poisson density', s))) > 0) then
          call bad_value(g, src, &
            trim(word('young poisson density', s)), '', 'is given with material = '//quote(trim(c%material))// &
            ': the material holds the body''s constants; give one or the other', err)
          return
        end if
      end do
    else if (find_asg(g, 'material') > 0) then
      ! material='' (an override back to young and poisson): both given, the body's own
      if (find_asg(g, 'young') == 0 .or. find_asg(g, 'poisson') == 0) then
        call bad_value(g, src, 'material', "''", &
          'leaves the body without a material: give young and poisson with it, or name a &material', err)
        return
      end if
    else if (len_trim(c%material) > 0) then
      do s = 1, 3
        if (find_asg(g, trim(word('young poisson density', s))) > 0) then
          call bad_value(g, src, &
            trim(word('young poisson density', s)), '', 'would change body '//i2s(id)//', which is of '// &
            'material = '//quote(trim(c%material))//': change the material (''&material name='// &
            quote(trim(c%material))//', ... /''), or give material='''' with young and poisson', err)
          return
        end if
      end do
    end if
    if (.not. abs(c%angle) <= 3600.0_wp) then
      call bad_value(g, src, 'angle', roundtrip(c%angle), &
        'is out of range: an angle in degrees, at most 3600 in magnitude', err)
      return
    end if
    c%id = b0%id
    do s = 1, MAX_SIDES
      if (c%bc(s) /= BC_DISPLACEMENT) c%u_side(:, s) = 0.0_wp
    end do
    if (find_asg(g, 'depth') > 0 .and. .not. c%depth > 0.0_wp) then
      call bad_value(g, src, 'depth', roundtrip(c%depth), &
        'must be > 0', err)
      return
    end if
    if (c%nz < 1) then
      call bad_value(g, src, 'nz', i2s(c%nz), 'must be >= 1 (cells along z)', err)
      return
    end if
    do s = 1, 5
      k = find_asg(g, trim(word('depth z0 nz front back', s)))
      if (k > 0 .and. len(st%box_var(id)%s) == 0) st%box_var(id)%s = 'line '//i2s(g%a(k)%line)//': '// &
        trim(word('depth z0 nz front back', s))//' = '//g%a(k)%value
    end do
    d%body(id) = c
    st%disp_given(:, id) = st%disp_given(:, id) .and. d%body(id)%bc == BC_DISPLACEMENT
  end subroutine apply_body

  !> A &traction group (deck or override): appends a traction.
  subroutine add_traction(g, src, d, st, origin, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    character(len=*), intent(in) :: origin
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(load_in_t), target :: t
    type(vars_t) :: v
    integer :: n

    call traction_vars(t, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call traction_form(g, src, t, d%nbody, err)
    if (err%failed()) return
    call check_stage(g, src, t%stage, err)
    if (err%failed()) return
    n = d%ntraction + 1
    call grow(d%traction, n)
    call grow(st%trac_at, n)
    d%ntraction = n
    d%traction(n)%body = t%body
    d%traction(n)%side = t%side
    d%traction(n)%group = t%group
    d%traction(n)%t0 = t%t0
    d%traction(n)%t1 = t%t1
    d%traction(n)%tx = t%tx
    d%traction(n)%ty = t%ty
    d%traction(n)%pressure = t%pressure
    d%traction(n)%stage = t%stage
    d%traction(n)%origin = '&traction at '//origin
    st%trac_at(n)%s = origin
  end subroutine add_traction

  !> A traction is on a side (side=, t0, t1) or on a group (group=, t0, tx, ty, pressure).
  subroutine traction_form(g, src, t, nbody, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(load_in_t), intent(inout) :: t
    integer, intent(in) :: nbody
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k
    do k = 1, 3
      if (NDIM == 3 .and. find_asg(g, trim(word('t1 tx ty', k))) > 0) then
        call die_at(src, g%line, &
          'in group &traction: '//trim(word('t1 tx ty', k))//' (a traction varying along x or y) is for '// &
          '2D decks; in a 3D deck a traction is t0 - pressure*n, constant over its side or group', err)
        return
      end if
    end do
    if (len_trim(t%group) > 0) then
      if (find_asg(g, 'side') > 0) then
        call die_at(src, g%line, 'in group &traction: give side= '// &
          '(a rectangle''s side) or group= (a named edge group), not both', err)
        return
      end if
      if (find_asg(g, 't1') > 0) then
        call die_at(src, g%line, 'in group &traction: t1 belongs to a '// &
          'side traction; on a group the traction is t0 + tx*x + ty*y - pressure*n', err)
        return
      end if
      call body_given(g, src, t%body, nbody, err)
      if (err%failed()) return
    else
      do k = 1, 3
        if (find_asg(g, trim(word('tx ty pressure', k))) > 0) then
          call die_at(src, g%line, &
            'in group &traction: '//trim(word('tx ty pressure', k))//' belongs to a group traction '// &
            '(group=''NAME''); on a side the traction is t0 + t1*s', err)
          return
        end if
      end do
      call body_and_side(g, src, t, nbody, err)
      if (err%failed()) return
    end if
  end subroutine traction_form

  !> A &body_force group (deck or override): a body force on one body or on every body.
  subroutine add_body_force(g, src, d, origin, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    character(len=*), intent(in) :: origin
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(body_force_cfg_t), target :: f
    type(vars_t) :: v
    integer :: n
    call body_force_vars(f, v)
    call read_group(g, src, v, err)
    if (err%failed()) return
    if (f%body < 0 .or. f%body > d%nbody) then
      call bad_value(g, src, 'body', i2s(f%body), &
        'does not exist: the bodies have '//ids_text(d%nbody)//', and 0 means every body', err)
      return
    end if
    call check_stage(g, src, f%stage, err)
    if (err%failed()) return
    n = d%nbody_force + 1
    call grow(d%body_force, n)
    d%nbody_force = n
    f%origin = '&body_force at '//origin
    d%body_force(n) = f
  end subroutine add_body_force

  !> A &material group: a new material (deck), or a change of the one it names (override;
  !! a new name there adds one). Its kind is that of the constants given; each constant in
  !! its range.
  subroutine add_material(g, src, d, origin, override, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    character(len=*), intent(in) :: origin
    logical, intent(in) :: override
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(material_cfg_t), target :: m
    type(vars_t) :: v
    character(len=*), parameter :: ISO = 'young poisson', &
      ORTHO = 'e1 e2 e3 nu12 nu13 nu23 g12', ANISO = 'c11 c12 c16 c22 c26 c66 c13 c23 c36 c33'
    character(len=40), parameter :: LISTS(3) = [character(len=40) :: ISO, ORTHO, ANISO]
    character(len=:), allocatable :: first_name
    integer :: n, k, j, kinds(3), kind
    real(wp) :: x
    call material_vars(m, v)
    call read_group(g, src, v, err)
    if (err%failed()) return
    if (len_trim(m%name) == 0) then
      call bad_value(g, src, 'name', "''", 'is empty: a material needs a name', err)
      return
    end if
    n = 0
    do k = 1, d%nmaterial
      if (d%material(k)%name == m%name) n = k
    end do
    if (n > 0 .and. .not. override) then
      call bad_value(g, src, 'name', quote(trim(m%name)), 'is used twice '// &
        '(also by the '//trim(d%material(n)%origin)//'); each material once', err)
      return
    end if
    if (n > 0) then            ! an override: the material's values, changed by the group's
      m = d%material(n)
      call material_vars(m, v)
      call read_group(g, src, v, err)
      if (err%failed()) return
    end if
    ! the kind: the constants given (in this group, or before it for an override)
    kinds = [(count_given(m, trim(LISTS(k))), k=1, 3)]
    if (count(kinds > 0) > 1) then
      first_name = ''
      do k = 1, 3
        if (kinds(k) == 0) cycle
        j = first_given(m, trim(LISTS(k)))
        first_name = first_name//merge(' and ', '     ', len(first_name) > 0)//trim(word(MAT_KIND_NAMES, k))// &
                     ' ('//trim(word(LISTS(k), j))//')'
      end do
      call die_at(src, g%line, 'in group &material: material '//quote(trim(m%name))//' has constants of '// &
        'two kinds: '//trim(adjustl(first_name))//'; give those of one kind: isotropic (young, poisson), '// &
        'orthotropic (e1, e2, e3, nu12, nu13, nu23, g12) or anisotropic (c11 to c66)', err)
      return
    end if
    if (all(kinds == 0)) then
      call die_at(src, g%line, 'in group &material: material '//quote(trim(m%name))// &
        ' has no elastic constant; give young and poisson (isotropic), e1, e2, nu12, g12 (orthotropic; '// &
        'e3, nu13, nu23 too in plane strain) or c11, c12, c22, c66 (anisotropic)', err)
      return
    end if
    kind = maxloc(kinds, 1)
    m%kind = merge(MAT_ISOTROPIC, merge(MAT_ORTHOTROPIC, MAT_ANISOTROPIC, kind == 2), kind == 1)
    if (m%kind == MAT_ISOTROPIC) then
      if (m%young == UNSET) then
        call die_at(src, g%line, 'in group &material: isotropic material '// &
          quote(trim(m%name))//' has poisson but no young; give both', err)
        return
      end if
      if (m%poisson == UNSET) then
        call die_at(src, g%line, 'in group &material: isotropic material '// &
          quote(trim(m%name))//' has young but no poisson; give both', err)
        return
      end if
      if (.not. m%young > 0.0_wp) then
        call bad_value(g, src, 'young', roundtrip(m%young), 'must be > 0 (Young''s modulus)', err)
        return
      end if
      call check_modulus(g, src, 'young', m%young, err)
      if (err%failed()) return
      if (.not. (m%poisson > -1.0_wp .and. m%poisson < 0.5_wp)) then
        call bad_value(g, src, 'poisson', &
          roundtrip(m%poisson), 'is out of range: it must satisfy -1 < poisson < 0.5', err)
        return
      end if
    end if
    do k = 1, 4
      call positive(trim(word('e1 e2 e3 g12', k)), [m%e1, m%e2, m%e3, m%g12], err)
      if (err%failed()) return
    end do
    do k = 1, 10               ! a stiffness constant may be 0 or negative, not beyond the range
      x = constant(m, trim(word(ANISO, k)))
      if (x /= UNSET .and. .not. abs(x) < MODULUS_MAX) then
        call bad_value(g, src, trim(word(ANISO, k)), roundtrip(x), &
          'is beyond '//sci(MODULUS_MAX)//' in magnitude, where a body''s stiffness stays within double '// &
          'precision; rescale the units', err)
        return
      end if
    end do
    if (.not. m%density >= 0.0_wp) then
      call bad_value(g, src, 'density', roundtrip(m%density), &
        'must be >= 0 (mass per volume)', err)
      return
    end if
    if (n == 0) then
      n = d%nmaterial + 1
      call grow(d%material, n)
      d%nmaterial = n
      m%origin = '&material at '//origin
    end if
    d%material(n) = m
  contains
    subroutine positive(name, vals, err)
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: vals(4)
      type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
      real(wp) :: x
      x = vals(k)
      if (x /= UNSET .and. .not. x > 0.0_wp) then
        call bad_value(g, src, name, roundtrip(x), 'must be > 0 (a modulus)', err)
        return
      end if
      if (x /= UNSET) then
        call check_modulus(g, src, name, x, err)
        if (err%failed()) return
      end if
    end subroutine positive
  end subroutine add_material

  !> A modulus [stress] (young, e1, ...) within (MODULUS_MIN, MODULUS_MAX), where a body's
  !! stiffness and flexibility stay within double precision: checked before the elastic law
  !! is computed (resolve_materials), which a modulus of 1e308 makes overflow.
  subroutine check_modulus(g, src, name, x, err)
    type(grp_t), intent(in) :: g             !< the group
    type(src_t), intent(in) :: src           !< where it comes from
    character(len=*), intent(in) :: name     !< the variable
    real(wp), intent(in) :: x                !< its value [stress]
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    if (.not. (x > MODULUS_MIN .and. x < MODULUS_MAX)) then
      call bad_value(g, src, name, roundtrip(x), &
        'is outside ['//sci(MODULUS_MIN)//', '//sci(MODULUS_MAX)//'], where a body''s stiffness and '// &
        'flexibility stay within double precision; rescale the units', err)
    end if
  end subroutine check_modulus

  !> How many of the constants `names` material m has.
  integer function count_given(m, names) result(n)
    type(material_cfg_t), intent(in) :: m
    character(len=*), intent(in) :: names
    n = 0
    if (first_given(m, names) > 0) n = 1
  end function count_given

  !> The first of the constants `names` (blank-separated) that m has, 0: none.
  integer function first_given(m, names) result(j)
    type(material_cfg_t), intent(in) :: m
    character(len=*), intent(in) :: names
    do j = 1, 10
      if (len_trim(word(names, j)) == 0) exit
      if (constant(m, trim(word(names, j))) /= UNSET) return
    end do
    j = 0
  end function first_given

  !> The constant `name` of material m (UNSET: not given).
  real(wp) function constant(m, name) result(x)
    type(material_cfg_t), intent(in) :: m
    character(len=*), intent(in) :: name
    select case (name)
    case ('young'); x = m%young
    case ('poisson'); x = m%poisson
    case ('e1'); x = m%e1
    case ('e2'); x = m%e2
    case ('e3'); x = m%e3
    case ('nu12'); x = m%nu12
    case ('nu13'); x = m%nu13
    case ('nu23'); x = m%nu23
    case ('g12'); x = m%g12
    case ('c11'); x = m%c11
    case ('c12'); x = m%c12
    case ('c16'); x = m%c16
    case ('c22'); x = m%c22
    case ('c26'); x = m%c26
    case ('c66'); x = m%c66
    case ('c13'); x = m%c13
    case ('c23'); x = m%c23
    case ('c36'); x = m%c36
    case default; x = m%c33
    end select
  end function constant

  !> A &region group: a part of a body made of a material of its own (deck), or a change of
  !! the region of that body and name (override).
  subroutine add_region(g, src, d, origin, override, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    character(len=*), intent(in) :: origin
    logical, intent(in) :: override
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(region_cfg_t), target :: r
    type(vars_t) :: v
    integer :: n, k
    call region_vars(r, v)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call body_given(g, src, r%body, d%nbody, err)
    if (err%failed()) return
    if (len_trim(r%name) == 0) then
      call bad_value(g, src, 'name', "''", 'is empty: name a physical surface '// &
        'of the body''s mesh file', err)
      return
    end if
    if (len_trim(r%material) == 0) then
      call bad_value(g, src, 'material', "''", 'is empty: a region is '// &
        'made of a &material, named here', err)
      return
    end if
    if (.not. abs(r%angle) <= 3600.0_wp) then
      call bad_value(g, src, 'angle', roundtrip(r%angle), &
        'is out of range: an angle in degrees, at most 3600 in magnitude', err)
      return
    end if
    n = 0
    do k = 1, d%nregion
      if (d%region(k)%body == r%body .and. d%region(k)%name == r%name) n = k
    end do
    if (n > 0 .and. .not. override) then
      call bad_value(g, src, 'name', quote(trim(r%name)), 'is a region of '// &
        'body '//i2s(r%body)//' twice (also the '//trim(d%region(n)%origin)//'); each region once', err)
      return
    end if
    if (n == 0) then
      n = d%nregion + 1
      call grow(d%region, n)
      d%nregion = n
    end if
    r%origin = '&region at '//origin
    d%region(n) = r
  end subroutine add_region

  !> A &boundary group (deck or override): prescribed components on a named edge group.
  subroutine add_boundary(g, src, d, origin, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    character(len=*), intent(in) :: origin
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(load_in_t), target :: t
    type(vars_t) :: v
    integer :: n

    call boundary_vars(t, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call body_given(g, src, t%body, d%nbody, err)
    if (err%failed()) return
    call check_stage(g, src, t%stage, err)
    if (err%failed()) return
    if (len_trim(t%group) == 0 .and. NDIM == 3) then
      call die_at(src, g%line, 'in group &boundary: no group; '// &
        'give group=''NAME'', a physical surface, curve or point of the body''s mesh (a box has ''left'', '// &
        '''right'', ''bottom'', ''top'', ''front'', ''back'')', err)
      return
    end if
    if (len_trim(t%group) == 0) then
      call die_at(src, g%line, 'in group &boundary: no group; give '// &
        'group=''NAME'', a physical curve of the body''s mesh (a rectangle has ''left'', ''right'', '// &
        '''bottom'', ''top'')', err)
      return
    end if
    if (find_asg(g, 'uz') > 0 .and. NDIM == 2) then
      call die_at(src, g%line, 'in group &boundary: uz = '// &
        roundtrip(t%uz)//' in a 2D deck: a plane body has no z displacement (a 3D deck: &scene dimension=3)', err)
      return
    end if
    if (find_asg(g, 'ux') == 0 .and. find_asg(g, 'uy') == 0 .and. find_asg(g, 'uz') == 0) then
      call die_at(src, g%line, &
        'in group &boundary: neither ux nor uy'//trim(merge(' nor uz', '       ', NDIM == 3))//' is given; give '// &
        'the components to prescribe (ux=0.0 for a roller on a vertical wall, ux=0.0, uy=0.0 to clamp)', err)
      return
    end if
    n = d%nboundary + 1
    call grow(d%boundary, n)
    d%nboundary = n
    d%boundary(n)%body = t%body
    d%boundary(n)%group = t%group
    d%boundary(n)%fix = [find_asg(g, 'ux') > 0, find_asg(g, 'uy') > 0, find_asg(g, 'uz') > 0]
    d%boundary(n)%u = [t%ux, t%uy, t%uz]
    d%boundary(n)%stage = t%stage
    d%boundary(n)%origin = '&boundary at '//origin
  end subroutine add_boundary

  !> The body= of a &traction, &displacement or &boundary: given, and 1 to nbody.
  subroutine body_given(g, src, body, nbody, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    integer, intent(in) :: body, nbody
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k
    logical :: missing
    k = find_asg(g, 'body')
    missing = k == 0
    if (.not. missing) missing = len_trim(g%a(k)%value) == 0
    if (missing) then
      call die_at(src, g%line, 'in group &'//g%name//': no body; give body=1 or body=2', err)
      return
    end if
    if (body < 1 .or. body > nbody) then
      call bad_value(g, src, 'body', i2s(body), &
        'does not exist: the bodies have '//ids_text(nbody), err)
    end if
  end subroutine body_given

  !> A body read from a mesh file: the rectangle's variables have no meaning; the path is
  !! made absolute, relative to the deck's folder (for a command-line override too).
  subroutine mesh_body(g, src, c, deck_path, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(body_cfg_t), intent(inout) :: c
    character(len=*), intent(in) :: deck_path
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    character(len=*), parameter :: RECT = 'x0 y0 width height nx ny element left right top bottom'
    integer :: k
    do k = 1, 11
      if (find_asg(g, trim(word(RECT, k))) > 0) then
        call die_at(src, g%line, 'in group &body: '// &
          trim(word(RECT, k))//' describes a built-in rectangle, but this body comes from mesh='''// &
          trim(c%mesh)//'''; give its conditions with &boundary and &traction on the mesh''s groups', err)
        return
      end if
    end do
    if (c%mesh(1:1) /= '/') then
      if (len(deck_folder(deck_path)) + len_trim(c%mesh) > len(c%mesh)) then
        call die_at(src, g%line, &
          'in group &body: the mesh path '''//trim(c%mesh)//''' in the deck''s folder '''//deck_folder(deck_path)// &
          ''' is '//i2s(len(deck_folder(deck_path)) + len_trim(c%mesh))//' characters long, longer than the '// &
          'system''s limit of '//i2s(len(c%mesh))//' (PATH_MAX)', err)
        return
      end if
      c%mesh = deck_folder(deck_path)//trim(c%mesh)
    end if
    c%bc = BC_FREE
  end subroutine mesh_body

  !> The absolute folder of the deck file, with a trailing '/' (the working folder for a
  !! deck read from /dev/, e.g. a pipe).
  function deck_folder(path) result(f)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: f
    character(len=4096) :: cwd
    integer :: k, stat
    call getcwd(cwd, stat)
    if (stat /= 0) cwd = '.'
    f = ''
    if (path(1:min(5, len(path))) /= '/dev/') then
      k = index(path, '/', back=.true.)
      if (k > 0) f = path(1:k)
    end if
    if (len(f) == 0) then
      f = trim(cwd)//'/'
    else if (f(1:1) /= '/') then
      f = trim(cwd)//'/'//f
    end if
  end function deck_folder

  !> A &displacement group (deck or override): prescribes a displacement on a side.
  subroutine apply_displacement(g, src, d, st, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(deck_t), intent(inout) :: d
    type(state_t), intent(inout) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    type(load_in_t), target :: t
    type(vars_t) :: v
    integer :: s, body
    character(len=:), allocatable :: side

    call displacement_vars(t, v, ALL_FORMS)
    call read_group(g, src, v, err)
    if (err%failed()) return
    call check_stage(g, src, t%stage, err)
    if (err%failed()) return
    call body_and_side(g, src, t, d%nbody, err)
    if (err%failed()) return
    if (len_trim(d%body(t%body)%mesh) > 0) then
      call die_at(src, g%line, 'in group &displacement: body '// &
        i2s(t%body)//' comes from a mesh file and has no sides; prescribe its displacement with '// &
        '&boundary body='//i2s(t%body)//', group=''NAME'', ux=..., uy=... /', err)
      return
    end if
    body = t%body
    s = t%side
    side = trim(side_names(s))
    if (d%body(body)%bc(s) == BC_CONTACT) then
      call bad_value(g, src, 'side', "'"//side//"'", &
        'is the contact side of body '//i2s(body)//'; a contact side cannot have a '// &
        'prescribed displacement', err)
      return
    end if
    if (d%body(body)%bc(s) == BC_CLAMPED .or. d%body(body)%bc(s) == BC_ROLLER) then
      call bad_value(g, src, &
        'side', "'"//side//"'", 'is '''//trim(bc_names(d%body(body)%bc(s)))//''' on body '//i2s(body)// &
        '; a side is either '''//trim(bc_names(d%body(body)%bc(s)))//''' or has a prescribed '// &
        'displacement: declare it '//side//'=''displacement'' (or ''free'') in its &body', err)
      return
    end if
    if (src%is_file) then
      if (st%disp_line(s, body) > 0) then
        call die_at(src, g%line, 'in group &displacement: side '''// &
          side//''' of body '//i2s(body)//' already has a prescribed displacement (line '// &
          i2s(st%disp_line(s, body))//')', err)
        return
      end if
      st%disp_line(s, body) = g%line
    end if
    d%body(body)%bc(s) = BC_DISPLACEMENT
    d%body(body)%u_side(:, s) = t%u
    d%body(body)%side_stage(s) = t%stage
    st%disp_given(s, body) = .true.
  end subroutine apply_displacement

  !> The stage= of a load group: >= 1 and at most MAX_STAGES.
  subroutine check_stage(g, src, stage, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    integer, intent(in) :: stage
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    if (stage < 1) then
      call bad_value(g, src, 'stage', i2s(stage), 'must be >= 1 (the stages are 1, 2, ...)', err)
      return
    end if
    if (stage > MAX_STAGES) then
      call bad_value(g, src, 'stage', i2s(stage), 'is out of range: a deck has at '// &
        'most '//i2s(MAX_STAGES)//' stages', err)
    end if
  end subroutine check_stage

  !> Check the body= and side= of a &traction or &displacement.
  subroutine body_and_side(g, src, t, nbody, err)
    type(grp_t), intent(in) :: g
    type(src_t), intent(in) :: src
    type(load_in_t), intent(in) :: t
    integer, intent(in) :: nbody
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    call body_given(g, src, t%body, nbody, err)
    if (err%failed()) return
    if (t%side == 0) then
      call die_at(src, g%line, 'in group &'//g%name//': no side; give '// &
        'side='//quoted_list(SIDE_CHOICES, ''), err)
    end if
  end subroutine body_and_side

  !> The scene's dimension, before the loads are read (they take NCOMP components): `&scene
  !! dimension`, else 3 where a body gives `depth` (a box), else 2; set for the run (space's
  !! set_dimension). A 2D deck with a box's variable, a 3D deck with a body that is neither a
  !! box nor a mesh file (a Gmsh volume mesh), a body of a mesh file with a box's variable, or
  !! a 3D deck with plane stress or axisymmetric bodies, is bad input naming the body and the
  !! line.
  subroutine resolve_dimension(path, d, st, err)
    character(len=*), intent(in) :: path          !< the deck
    type(deck_t), intent(inout) :: d              !< its dimension resolved
    type(state_t), intent(in) :: st               !< where each body's box variables were given
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: b, first
    character(len=:), allocatable :: why
    first = 0
    do b = d%nbody, 1, -1
      if (d%body(b)%depth /= UNSET) first = b
    end do
    if (d%dimension == 0) d%dimension = merge(3, 2, first > 0)
    do b = 1, d%nbody
      if (d%dimension == 2 .and. len(st%box_var(b)%s) > 0) then
        call err%set(ERR_INPUT, path//': '// &
          st%body_at(b)%s//' (body '//i2s(b)//'), '//st%box_var(b)%s//': a variable of a box, in a 2D '// &
          'deck (&scene dimension=2); give &scene dimension=3 (or leave dimension out) for 3D bodies')
        return
      end if
      if (d%dimension == 3 .and. len_trim(d%body(b)%mesh) > 0 .and. len(st%box_var(b)%s) > 0) then
        call err%set( &
          ERR_INPUT, path//': '//st%body_at(b)%s//' (body '//i2s(b)//'), '//st%box_var(b)%s//': a variable of a '// &
          'box, but this body comes from mesh='''//trim(d%body(b)%mesh)//''' (a Gmsh volume mesh, its geometry the '// &
          'file''s); give its conditions with &boundary and &traction on the mesh''s physical surfaces')
        return
      end if
      if (d%dimension == 3 .and. d%body(b)%depth == UNSET .and. len_trim(d%body(b)%mesh) == 0) then
        why = '&scene dimension=3'
        if (first > 0) why = 'the depth of body '//i2s(first)
        call err%set(ERR_INPUT, path//': '//st%body_at(b)%s//' (body '//i2s(b)//') gives no depth, in a 3D '// &
          'deck ('//why//'): every body of a 3D deck is a box (give its z0, depth and nz) or a Gmsh volume '// &
          'mesh (mesh=)')
        return
      end if
    end do
    if (d%dimension == 3 .and. (d%axisymmetric .or. .not. d%plane_strain)) then
      call err%set(ERR_INPUT, path// &
        ': &scene plane='''//trim(merge('axisymmetric', 'stress      ', d%axisymmetric))//''' in a 3D deck: '// &
        'plane strain, plane stress and axisymmetric bodies are 2D models; leave plane out of a 3D deck')
      return
    end if
    call set_dimension(d%dimension)
  end subroutine resolve_dimension

  ! ---- growing lists (generic grow) --------------------------------------------------------

  !> The size of a list that must hold `n` items and holds `have`: at least 4, doubled.
  pure integer function capacity(n, have)
    integer, intent(in) :: n, have
    capacity = max(4, 2*have, n)
  end function capacity

  subroutine grow_pairs(list, n)
    type(contact_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(contact_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_pairs

  subroutine grow_strs(list, n)
    type(str_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(str_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_strs

  subroutine grow_tractions(list, n)
    type(traction_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(traction_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_tractions

  subroutine grow_body_forces(list, n)
    type(body_force_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(body_force_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_body_forces

  subroutine grow_materials(list, n)
    type(material_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(material_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_materials

  subroutine grow_regions(list, n)
    type(region_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(region_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_regions

  subroutine grow_boundaries(list, n)
    type(boundary_cfg_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(boundary_cfg_t), allocatable :: tmp(:)
    if (.not. allocated(list)) allocate (list(0))
    if (n <= size(list)) return
    allocate (tmp(capacity(n, size(list))))
    tmp(1:size(list)) = list
    call move_alloc(tmp, list)
  end subroutine grow_boundaries

end module deck_checks
