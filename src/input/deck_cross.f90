!> The checks across the deck's groups, once the deck and its overrides are read
!! (`check_cross`): every body in a contact pair and a group of a body in one pair at most;
!! the two-body form's contact sides or groups, or the pair form's groups; prescribed
!! displacements and loads. Every bad input is returned as an `error_t` (ERR_INPUT) naming the
!! source, the group's line and the value.
module deck_cross
  use kinds, only: wp
  use errors, only: error_t, warn, ERR_INPUT
  use strings, only: i2s, roundtrip, word
  use sorting, only: merge_sort_by_keys
  use config, only: MAX_SIDES, FRICTION_NONE, FRICTION_CHOICES, deck_t, body_cfg_t, elastic_law_t, MAT_KIND_NAMES, SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, side_names, BC_CLAMPED, &
                    BC_CONTACT, BC_DISPLACEMENT, bc_names, STEPS_UNSET, stage_count
  use deck_checks, only: state_t
  use material_laws, only: isotropic_law, material_law
  implicit none (type, external)
  private

  public :: check_cross, resolve_materials

contains

  !> The checks across groups, once the deck and its overrides are read: every body in a
  !! pair, a group of a body in one pair at most; then the two-body form's contact sides or
  !! groups, or the pair form's groups; prescribed displacements and loads.
  subroutine check_cross(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: b, s, nc
    character(len=:), allocatable :: p, lst
    logical :: groups

    p = st%path//': '
    call check_stages(d, st, err)
    if (err%failed()) return
    if (d%dimension == 3) then
      call check_solid(d, st, err)
      if (err%failed()) return
    end if
    if (d%npair == 0) then
      call err%set(ERR_INPUT, p//'the deck has '//i2s(d%nbody)//' bodies and no '// &
        '&contact; name each contact pair with &contact bodies=A,B, groups=''GA'',''GB'' /')
      return
    end if
    call check_pairs(d, st, err)
    if (err%failed()) return
    if (d%pairs_named) then
      call check_named(d, st, err)
      if (err%failed()) return
      return
    end if
    groups = len_trim(d%pair(1)%body_group(1)) > 0 .or. len_trim(d%pair(1)%body_group(2)) > 0
    if (groups) then
      call check_groups(d, st, err)
      if (err%failed()) return
      return
    end if
    do b = 1, 2
      if (len_trim(d%body(b)%mesh) > 0) then
        call err%set(ERR_INPUT, p//'body '//i2s(b)//' ('// &
          st%body_at(b)%s//') comes from a mesh file: name the contact surfaces with &contact '// &
          'body1_group=''NAME1'', body2_group=''NAME2'' /')
        return
      end if
    end do
    do b = 1, 2
      nc = count(d%body(b)%bc == BC_CONTACT)
      if (nc /= 1) then
        lst = ''
        do s = 1, MAX_SIDES
          if (d%body(b)%bc(s) == BC_CONTACT) lst = lst//merge(', ', '  ', len(lst) > 0)//trim(side_names(s))
        end do
        if (nc == 0) then
          call err%set(ERR_INPUT, p//'body '//i2s(b)//' ('//st%body_at(b)%s//') has no '// &
            '''contact'' side; each body needs exactly one ('//side_list(d%body(b))//')')
          return
        else
          call err%set(ERR_INPUT, p//'body '//i2s(b)//' ('//st%body_at(b)%s//') has '//i2s(nc)// &
            ' ''contact'' sides ('//trim(adjustl(lst))//'); each body needs exactly one')
          return
        end if
      end if
    end do

    ! whether the two sides face each other, overlap and how their nodes pair is the mortar
    ! interface's business, as for named groups (condense: build_interface)

    ! support against rigid motion is the mesh's business (assembly: a body the supports
    ! leave free is held only by contact, and module floating checks that the contact can)

    do b = 1, 2
      call check_disp_given(d, st, b, .true., err)
      if (err%failed()) return
    end do

    call check_loads(d, st, err)
    if (err%failed()) return
  end subroutine check_cross

  !> What a 3D deck cannot have yet: a parabolic gap, materials other than isotropic
  !! young and poisson, regions; each refusal names the group.
  subroutine check_solid(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k
    character(len=:), allocatable :: p
    p = st%path//': '
    do k = 1, d%npair
      if (d%pair(k)%gap_radius > 0.0_wp) then
        call err%set(ERR_INPUT, p//st%pair_at(k)%s//': gap_radius = '// &
          roundtrip(d%pair(k)%gap_radius)//' in a 3D deck: the parabolic gap is a 2D profile; in 3D the gap is '// &
          'the geometry''s')
        return
      end if
    end do
    do k = 1, d%nbody
      if (len_trim(d%body(k)%material) > 0) then
        call err%set(ERR_INPUT, p//st%body_at(k)%s//' (body '//i2s(k)// &
          '): material = '''//trim(d%body(k)%material)//''' in a 3D deck: a solid body is isotropic for now; '// &
          'give young and poisson')
        return
      end if
    end do
    if (d%nregion > 0) then
      call err%set(ERR_INPUT, p//'&region in a 3D deck (the '//trim(d%region(1)%origin)// &
        '): a region is made of a &material, and a solid body is of one isotropic material (young, poisson) '// &
        'for now')
    end if
  end subroutine check_solid

  !> The load stages: with several, each of 1 .. the largest stage= has a load (a traction,
  !! or a nonzero prescribed displacement); &solver load_steps has one value or one per stage.
  subroutine check_stages(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: nstage, s, b, given, i
    logical :: loaded
    character(len=:), allocatable :: lst
    nstage = stage_count(d)
    do s = 1, merge(nstage, 0, nstage > 1)   ! one stage: an unloaded deck is a deck (a gap closed by nothing)
      loaded = any(d%traction(1:d%ntraction)%stage == s)
      do i = 1, d%nbody_force
        associate (f => d%body_force(i))
          if (f%stage == s .and. any(f%gravity /= 0.0_wp .or. f%force /= 0.0_wp)) loaded = .true.
        end associate
      end do
      do i = 1, d%nboundary
        associate (c => d%boundary(i))
          if (c%stage == s .and. any(c%fix .and. c%u /= 0.0_wp)) loaded = .true.
        end associate
      end do
      if (d%npair > 0) then
        if (any(d%pair(1:d%npair)%interference_stage == s)) loaded = .true.
      end if
      do b = 1, d%nbody
        associate (c => d%body(b))
          if (any(c%bc == BC_DISPLACEMENT .and. c%side_stage == s .and. &
                  (c%u_side(1, :) /= 0.0_wp .or. c%u_side(2, :) /= 0.0_wp))) loaded = .true.
        end associate
      end do
      if (.not. loaded) then
        call err%set(ERR_INPUT, st%path//': stage = '//i2s(s)//' has no load: no &traction or '// &
          '&body_force, '// &
          'and no &displacement or &boundary with a nonzero value, has stage='//i2s(s)//' (the stages are 1 to '// &
          'the largest stage= given, '//i2s(nstage)//', each with a load; a zero displacement is a support, '// &
          'no load)')
        return
      end if
    end do
    given = count(d%solver%load_steps /= STEPS_UNSET)
    if (given > 1 .and. given /= nstage) then
      lst = i2s(d%solver%load_steps(1))
      do i = 2, given
        lst = lst//','//i2s(d%solver%load_steps(i))
      end do
      call err%set(ERR_INPUT, st%path//': in group &solver: load_steps = '//lst//' has '//i2s(given)// &
        ' values for '//i2s(nstage)//' stage'//trim(merge('s', ' ', nstage > 1))//' (the largest stage= of '// &
        'the load groups); give one value for every stage, or one per stage')
    end if
  end subroutine check_stages

  !> A gravity needs a density on every body it acts on (in one of its materials at least;
  !! the laws resolved).
  subroutine check_body_forces(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: i, b
    character(len=:), allocatable :: on
    do i = 1, d%nbody_force
      associate (f => d%body_force(i))
        if (all(f%gravity == 0.0_wp)) cycle
        on = 'every body'
        if (f%body > 0) on = 'body '//i2s(f%body)
        do b = 1, d%nbody
          if (f%body /= 0 .and. f%body /= b) cycle
          if (maxval(d%body(b)%law%density) > 0.0_wp) cycle
          if (len_trim(d%body(b)%material) > 0) then
            call err%set(ERR_INPUT, st%path//': the '//trim(f%origin)// &
              ' gives gravity = '//roundtrip(f%gravity(1))//', '//roundtrip(f%gravity(2))//' on '//on//', but body '// &
              i2s(b)//' ('//st%body_at(b)%s//') is of material '''//trim(d%body(b)%material)//''', whose '// &
              'density = 0: give the &material density= (mass per volume), or a force per volume with force=')
            return
          end if
          call err%set(ERR_INPUT, st%path//': the '//trim(f%origin)//' gives gravity = '// &
            roundtrip(f%gravity(1))//', '//roundtrip(f%gravity(2))//' on '//on//', but body '//i2s(b)//' ('//st%body_at(b)%s//') has density = 0: give it '// &
            'density= (mass per volume), or a force per volume with force=')
          return
        end do
      end associate
    end do
  end subroutine check_body_forces

  !> Side tractions on rectangles: not on a contact side; no effect on a prescribed side.
  subroutine check_loads(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: i, s
    character(len=:), allocatable :: p
    p = st%path//': '
    do i = 1, d%ntraction
      associate (t => d%traction(i))
        if (len_trim(t%group) > 0) cycle
        if (len_trim(d%body(t%body)%mesh) > 0) then
          call err%set(ERR_INPUT, p//'the &traction at '// &
            st%trac_at(i)%s//' loads side '''//trim(side_names(t%side))//''' of body '//i2s(t%body)// &
            ', which comes from a mesh file and has no sides; load a group: group=''NAME''')
          return
        end if
        s = d%body(t%body)%bc(t%side)
        if (s == BC_CONTACT) then
          call err%set(ERR_INPUT, p//'the &traction at '//st%trac_at(i)%s// &
            ' loads side '''//trim(side_names(t%side))//''' of body '//i2s(t%body)//', which is '// &
            'its contact side; a contact side carries only contact forces')
          return
        end if
        if (s == BC_CLAMPED .or. s == BC_DISPLACEMENT) call warn(p// &
          'the &traction at '//st%trac_at(i)%s//' loads side '''//trim(side_names(t%side))// &
          ''' of body '//i2s(t%body)//', which has a prescribed displacement ('''// &
          trim(bc_names(s))//'''); that traction has no effect')
      end associate
    end do
  end subroutine check_loads

  !> Contact on named groups (mortar): both groups given, no rectangle side declared
  !! 'contact', sides with 'displacement' given. Supports and group names are checked on
  !! the meshes (module assembly, condense).
  subroutine check_groups(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: b
    character(len=:), allocatable :: p
    p = st%path//': '
    do b = 1, 2
      if (len_trim(d%pair(1)%body_group(b)) == 0) then
        call err%set(ERR_INPUT, p//'&contact names '// &
          'the contact group of one body only; give both, body1_group=''NAME1'', body2_group=''NAME2''')
        return
      end if
      if (any(d%body(b)%bc == BC_CONTACT)) then
        call err%set(ERR_INPUT, p//'body '//i2s(b)//' ('// &
          st%body_at(b)%s//') declares a ''contact'' side, but &contact names the contact groups; '// &
          'use one or the other (a rectangle''s sides are the groups ''left'', ''right'', '// &
          '''bottom'', ''top'')')
        return
      end if
      call check_disp_given(d, st, b, .false., err)
      if (err%failed()) return
    end do
    call check_loads(d, st, err)
    if (err%failed()) return
  end subroutine check_groups

  !> Every body is in a pair, and no group of a body is in two pairs with the same other
  !! body (a surface may touch several bodies: a lid on two blocks): the pairs' ends
  !! bucketed by body, each bucket sorted by group name (linear in the pairs but for the
  !! sort of a body's own ends).
  subroutine check_pairs(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer, allocatable :: first(:), ends(:), fill(:), ebody(:), partner(:)
    character(len=128), allocatable :: gname(:)
    integer :: k, j, e, b, n, i1, i2
    n = 2*d%npair
    allocate (first(d%nbody + 1), fill(d%nbody), ends(n), ebody(n), partner(n), gname(n))
    first = 0
    do k = 1, d%npair
      do j = 1, 2
        e = 2*(k - 1) + j
        ebody(e) = d%pair(k)%bodies(j)
        partner(e) = d%pair(k)%bodies(3 - j)
        gname(e) = d%pair(k)%body_group(j)
        first(ebody(e) + 1) = first(ebody(e) + 1) + 1
      end do
    end do
    do b = 1, d%nbody
      if (first(b + 1) == 0) then
        call err%set(ERR_INPUT, st%path//': body '//i2s(b)//' ('// &
          st%body_at(b)%s//') is in no contact pair; every body touches another: add &contact '// &
          'bodies='//i2s(b)//',B, groups=''GA'',''GB'' / for it')
        return
      end if
    end do
    first(1) = 1
    do b = 1, d%nbody
      first(b + 1) = first(b + 1) + first(b)
    end do
    fill = first(1:d%nbody)
    do e = 1, n
      ends(fill(ebody(e))) = e
      fill(ebody(e)) = fill(ebody(e)) + 1
    end do
    do b = 1, d%nbody
      if (first(b + 1) - first(b) < 2) cycle
      call sort_names(ends(first(b):first(b + 1) - 1), gname)
      ! within each run of equal names, no two ends with the same partner body
      do j = first(b), first(b + 1) - 2
        i1 = ends(j)
        if (len_trim(gname(i1)) == 0) cycle
        do k = j + 1, first(b + 1) - 1
          i2 = ends(k)
          if (gname(i2) /= gname(i1)) exit
          if (partner(i1) /= partner(i2)) cycle
          call err%set(ERR_INPUT, st%path//': the '//st%pair_at((min(i1, i2) + 1)/2)%s//' and the '// &
            st%pair_at((max(i1, i2) + 1)/2)%s//' both name group '''//trim(gname(i1))//''' of body '// &
            i2s(b)//' with body '//i2s(partner(i1))//'; a group of a body is in one pair with each '// &
            'other body at most')
          return
        end do
      end do
    end do
  end subroutine check_pairs

  !> Sort the indices `idx` by `key(idx(i))`, ascending (stable merge sort): the names
  !! compared by their character codes, as the character comparison does.
  subroutine sort_names(idx, key)
    integer, intent(inout) :: idx(:)          !< indices into key, sorted on return
    character(len=*), intent(in) :: key(:)    !< the names
    integer, allocatable :: codes(:, :), local(:)
    integer :: i, c
    ! the codes of the names idx points at only (not of every name: a deck of 10,000 bodies
    ! sorts each body's few ends, and coding all 2 npair names each time was quadratic)
    allocate (codes(len(key), size(idx)))
    do i = 1, size(idx)
      do c = 1, len(key)
        codes(c, i) = ichar(key(idx(i))(c:c))
      end do
    end do
    local = [(i, i=1, size(idx))]
    call merge_sort_by_keys(local, codes)
    idx = idx(local)
  end subroutine sort_names

  !> The pair form: a rectangle's groups are its sides, none of them declared 'contact'
  !! (the pairs name them); sides with 'displacement' given; loads.
  subroutine check_named(d, st, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: k, j, b
    do k = 1, d%npair
      do j = 1, 2
        b = d%pair(k)%bodies(j)
        if (len_trim(d%body(b)%mesh) > 0) cycle
        if (.not. any(side_names == d%pair(k)%body_group(j))) then
          call err%set(ERR_INPUT, st%path// &
            ': the '//st%pair_at(k)%s//' names group '''//trim(d%pair(k)%body_group(j))//''' of body '// &
            i2s(b)//', a rectangle, whose groups are its sides ''left'', ''right'', ''bottom'', ''top''')
          return
        end if
      end do
    end do
    do b = 1, d%nbody
      if (any(d%body(b)%bc == BC_CONTACT)) then
        call err%set(ERR_INPUT, st%path//': body '//i2s(b)//' ('// &
          st%body_at(b)%s//') declares a ''contact'' side, but the deck names its pairs with &contact '// &
          'bodies=A,B, groups=...; a pair names a rectangle''s contact side as its group (''left'', '// &
          '''right'', ''bottom'', ''top''), declared ''free''')
        return
      end if
      call check_disp_given(d, st, b, len_trim(d%body(b)%mesh) == 0, err)
      if (err%failed()) return
    end do
    call check_loads(d, st, err)
    if (err%failed()) return
  end subroutine check_named

  !> Every side of body b declared 'displacement' has its &displacement (with `hint`, the
  !! message shows the group to add).
  subroutine check_disp_given(d, st, b, hint, err)
    type(deck_t), intent(in) :: d
    type(state_t), intent(in) :: st
    integer, intent(in) :: b
    logical, intent(in) :: hint
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: s
    character(len=:), allocatable :: add
    do s = 1, MAX_SIDES
      if (d%body(b)%bc(s) /= BC_DISPLACEMENT .or. st%disp_given(s, b)) cycle
      add = ''
      if (hint) add = '; add &displacement body='//i2s(b)//', side='''//trim(side_names(s))//''', u=ux, uy /'
      call err%set(ERR_INPUT, st%path//': body '//i2s(b)//' ('//st%body_at(b)%s//') declares its '// &
        trim(side_names(s))//' side ''displacement'' but no &displacement group gives that displacement'//add)
      return
    end do
  end subroutine check_disp_given

  function side_list(b) result(s)
    type(body_cfg_t), intent(in) :: b
    character(len=:), allocatable :: s
    s = 'left='''//trim(bc_names(b%bc(SIDE_LEFT)))//''', right='''//trim(bc_names(b%bc(SIDE_RIGHT)))// &
      ''', top='''//trim(bc_names(b%bc(SIDE_TOP)))//''', bottom='''//trim(bc_names(b%bc(SIDE_BOTTOM)))//''''
  end function side_list

  !> Each body's elastic laws (body_cfg_t%law): law(1) its own material (its &material, or
  !! young and poisson), then one per &region of the body, in deck order. Bad input: a
  !! material= naming no &material, a &region on a rectangle or of an unknown material, a
  !! material the scene's model cannot use (a constant missing, a tensor not positive definite).
  subroutine resolve_materials(d, st, err)
    type(deck_t), intent(inout) :: d
    type(state_t), intent(in) :: st
    type(error_t), intent(out) :: err   !< ERR_INPUT and the message on bad input
    integer :: b, k, i, n
    type(error_t) :: lerr   ! a material's law (refused in the first loop, known good after it)

    do k = 1, d%nmaterial     ! every material, used or not, is one the scene's model can use
      block
        type(elastic_law_t) :: law
        call material_law(d%material(k), 0.0_wp, d%plane_strain, law, lerr, d%axisymmetric)
        if (lerr%failed()) then
          call err%set(ERR_INPUT, st%path//': the '//trim(d%material(k)%origin)// &
            ' (material '''//trim(d%material(k)%name)//''', '//trim(word(MAT_KIND_NAMES, d%material(k)%kind))// &
            ', in '//trim(merge('axisymmetric', merge('plane strain', 'plane stress', d%plane_strain), &
            d%axisymmetric))//'): '//lerr%message)
          return
        end if
      end block
    end do
    do b = 1, d%nbody
      n = 1
      do i = 1, d%nregion
        if (d%region(i)%body == b) n = n + 1
      end do
      if (allocated(d%body(b)%law)) deallocate (d%body(b)%law)
      allocate (d%body(b)%law(n))
      if (len_trim(d%body(b)%material) == 0) then
        call isotropic_law(d%body(b)%young, d%body(b)%poisson, d%plane_strain, d%body(b)%law(1))
        d%body(b)%law(1)%density = d%body(b)%density
      else
        k = material_index(d, d%body(b)%material)
        if (k == 0) then
          call err%set(ERR_INPUT, st%path//': body '//i2s(b)//' ('//st%body_at(b)%s//'): material = '''// &
            trim(d%body(b)%material)//''' names no &material ('//material_names(d)//')')
          return
        end if
        call material_law(d%material(k), d%body(b)%angle, d%plane_strain, d%body(b)%law(1), lerr, d%axisymmetric)
      end if
      n = 1
      do i = 1, d%nregion
        if (d%region(i)%body /= b) cycle
        n = n + 1
        if (len_trim(d%body(b)%mesh) == 0) then
          call err%set(ERR_INPUT, st%path//': the '// &
            trim(d%region(i)%origin)//' is on body '//i2s(b)//', a rectangle ('//st%body_at(b)%s// &
            '): a region is a physical surface of a mesh file; a rectangle is of one material')
          return
        end if
        k = material_index(d, d%region(i)%material)
        if (k == 0) then
          call err%set(ERR_INPUT, st%path//': the '//trim(d%region(i)%origin)//': material = '''// &
            trim(d%region(i)%material)//''' names no &material ('//material_names(d)//')')
          return
        end if
        d%body(b)%law(n)%region = d%region(i)%name
        call material_law(d%material(k), d%region(i)%angle, d%plane_strain, d%body(b)%law(n), lerr, d%axisymmetric)
      end do
    end do
    call check_body_forces(d, st, err)
    if (err%failed()) return
    if (d%axisymmetric) then    ! a rectangle's section lies at x >= 0
      do b = 1, d%nbody
        if (len_trim(d%body(b)%mesh) > 0) cycle
        if (d%body(b)%x0 < 0.0_wp) then
          call err%set(ERR_INPUT, st%path//': body '//i2s(b)//' ('// &
            st%body_at(b)%s//'): x0 = '//roundtrip(d%body(b)%x0)//' is below the axis: with plane = '// &
            '''axisymmetric'' x is the radius, x0 >= 0')
          return
        end if
      end do
    end if
  end subroutine resolve_materials

  integer function material_index(d, name) result(k)
    type(deck_t), intent(in) :: d
    character(len=*), intent(in) :: name
    do k = 1, d%nmaterial
      if (d%material(k)%name == name) return
    end do
    k = 0
  end function material_index

  !> The deck's materials for a message: 'the materials are 'a', 'b'' or 'the deck has no &material'.
  function material_names(d) result(s)
    type(deck_t), intent(in) :: d
    character(len=:), allocatable :: s
    integer :: k
    if (d%nmaterial == 0) then
      s = 'the deck has no &material'
      return
    end if
    s = 'the materials are'
    do k = 1, d%nmaterial
      s = s//trim(merge(', ', '  ', k > 1))//' '''//trim(d%material(k)%name)//''''
    end do
  end function material_names

end module deck_cross
