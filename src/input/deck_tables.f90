!> The variable tables of the deck's groups: one `*_vars` routine per group binds each
!! variable the group may set to its place in `config`'s settings (or in a `scene_in_t` /
!! `load_in_t` holding what is read before it is checked), with its description, unit and
!! range. The same table reads the group, renders it back and documents it: a new setting
!! is its field in `config` and one line here.
module deck_tables
  use kinds, only: wp
  use space, only: NDIM, NCOMP
  use namelist_vars, only: vars_t
  use config, only: deck_t, body_cfg_t, body_force_cfg_t, material_cfg_t, region_cfg_t, UNSET, contact_cfg_t, solver_cfg_t, output_cfg_t, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, SIDE_FRONT, SIDE_BACK, BC_FREE, &
                    METHOD_CHOICES, ROBIN_CHOICES, STOP_CHOICES, FACTOR_CHOICES, &
                    ORDER_CHOICES, ACCEL_CHOICES, XDMF_CHOICES, INNER_CHOICES, SIDE_CHOICES, BC_CHOICES, ELEMENT_CHOICES, PLANE_CHOICES, &
                    UNITS_CHOICES, FRICTION_CHOICES, OVERLAP_CHOICES, STEPS_UNSET
  implicit none (type, external)
  private

  public :: scene_in_t, load_in_t
  public :: ALL_FORMS, SIDE_FORM, GROUP_FORM, GIVEN_FORM, TWO_BODY_FORM, PAIR_FORM
  public :: scene_vars, body_vars, traction_vars, boundary_vars, displacement_vars, contact_vars, &
            solver_vars, output_vars, body_force_vars, material_vars, region_vars

  ! the documentation of `stage`, shared by the load groups
  !> The range of a modulus (config's MODULUS_MIN, MODULUS_MAX; deck_checks' check_modulus)
  character(len=*), parameter :: MODULUS_RANGE = '> 0; within [7.458e-149, 1.341e148] (double precision)'
  character(len=*), parameter :: STAGE_DOC = &
    'the load stage that applies it: stage s ramps its loads from 0 to their full value over its '// &
    '`&solver load_steps`, the earlier stages'' loads held at full value, the later ones'' at 0 '// &
    '(the stages are 1 to the largest `stage` given, each with a load). Rendered only when not 1'

  ! the documentation shared by the three unit names of &scene
  character(len=*), parameter :: UNIT_NAME_DOC = &
    'With `units=''SI''` or `''mm-N-MPa''` it is set by `units` (a different name given is bad '// &
    'input); with `''custom''` it is free but not empty'

  !> The variables of &scene that are not stored as they are read.
  type :: scene_in_t
    integer :: plane = 1                        ! PLANE_CHOICES code
  end type scene_in_t

  !> A &traction, &displacement or &boundary as read, before it is checked and stored.
  type :: load_in_t
    integer :: body = 0
    integer :: side = 0                         ! SIDE_*; 0 = not given
    character(len=128) :: group = ''            ! edge group ('' = not given)
    real(wp) :: t0(3) = 0.0_wp, t1(3) = 0.0_wp  ! traction (NCOMP components read; t1 plane only)
    real(wp) :: tx(3) = 0.0_wp, ty(3) = 0.0_wp  ! traction gradient (group; plane only)
    real(wp) :: pressure = 0.0_wp               ! normal pressure (group)
    real(wp) :: u(3) = 0.0_wp                   ! displacement (NCOMP components read)
    real(wp) :: ux = 0.0_wp, uy = 0.0_wp, uz = 0.0_wp   ! &boundary components
    logical :: fix(3) = .false.                 ! &boundary, rendering: the components given
    integer :: stage = 1                        ! load stage
  end type load_in_t

  ! which variables a table holds: all (reading), or those of one form (rendering)
  integer, parameter :: ALL_FORMS = 0, SIDE_FORM = 1, GROUP_FORM = 2, GIVEN_FORM = 3
  ! the two forms of &contact: bodies 1 and 2 (body1_group, body2_group), or a named pair
  integer, parameter :: TWO_BODY_FORM = 6, PAIR_FORM = 7

contains


  !> &scene. The units named here are the ones the other tables' unit column refers to.
  subroutine scene_vars(d, sc, v, rendering)
    type(deck_t), target, intent(inout) :: d
    type(scene_in_t), target, intent(inout) :: sc
    type(vars_t), intent(out) :: v
    logical, intent(in), optional :: rendering    ! .true.: the effective deck (dimension only when 3)
    logical :: all_vars
    all_vars = .true.
    if (present(rendering)) all_vars = .not. rendering
    call v%str('title', d%title, doc='free text, stored in the result file')
    if (all_vars .or. d%dimension == 3) call v%int('dimension', d%dimension, range='2 or 3', &
      doc='`2`: plane (or axisymmetric) bodies, x and y; `3`: solid bodies (boxes: `&body` with '// &
      '`z0`, `depth`, `nz`), x, y and z, every vector of the deck with three components. Not '// &
      'given: 3 where a `&body` gives `depth`, else 2; a deck is one or the other as a whole. '// &
      'Rendered only when 3')
    if (all_vars .or. NDIM == 2) call v%enum('plane', sc%plane, PLANE_CHOICES, doc='`''strain''` (plane strain), `''stress''` '// &
      '(plane stress) or `''axisymmetric''`: every body a body of revolution about the y axis, '// &
      'drawn by its meridian section at x = r >= 0 (y = z); nodes on the axis have ur = 0, a '// &
      'motion along x or a rotation is no rigid motion, and every load, reaction and contact '// &
      'force is per radian (the whole circumference: 2 pi times)')
    call v%enum('units', d%units%system, UNITS_CHOICES, doc='the units of the deck''s numbers, '// &
      'named in the result file, the plots and the summary (the solver is unit-free): `''SI''` (m, '// &
      'N, Pa), `''mm-N-MPa''` (mm, N, MPa: consistent, N/mm^2 = MPa) or `''custom''` (the names '// &
      'given by `length_unit`, `force_unit`, `stress_unit`)')
    call v%str('length_unit', d%units%length, doc='name of the length unit. '//UNIT_NAME_DOC)
    call v%str('force_unit', d%units%force, doc='name of the force unit. '//UNIT_NAME_DOC)
    call v%str('stress_unit', d%units%stress, doc='name of the stress unit (force/length^2). '// &
      UNIT_NAME_DOC)
  end subroutine scene_vars

  !> &body: `form` ALL_FORMS reads every variable; SIDE_FORM renders a rectangle,
  !! GROUP_FORM a body from a mesh file.
  subroutine body_vars(b, v, form)
    type(body_cfg_t), target, intent(inout) :: b
    type(vars_t), intent(out) :: v
    integer, intent(in) :: form
    call v%int('id', b%id, range='1 to N', required=.true., doc='which body; the N bodies of '// &
      'the deck have the ids 1 to N, each once. An override of `&body` changes the body it '// &
      'names: `''&body id=2, young=1e9 /''`')
    if (form /= SIDE_FORM) then
      call v%str('mesh', b%mesh, doc='a Gmsh mesh file, MSH 4.1 ASCII, holding the body''s '// &
        'cells (3-node triangles and 4-node quadrilaterals, mixed allowed; in a 3D deck 4-node '// &
        'tetrahedra and 8-node hexahedra, mixed allowed); a path relative to the deck''s folder '// &
        '(for an override too); `''''`: the built-in rectangle (box)')
      call v%str('region', b%region, doc='the physical surface of the file that is this body '// &
        '(in a 3D deck its physical volume; one file may hold both bodies); `''''`: the file''s '// &
        'only physical surface (volume), or every 2D (3D) cell if the file has none')
    end if
    if (form /= GROUP_FORM) then
      call v%real('x0', b%x0, unit='[length]', doc='x of the lower-left corner')
      call v%real('y0', b%y0, unit='[length]', doc='y of the lower-left corner')
      call v%real('width', b%width, unit='[length]', range='> 0', doc='extent in x')
      call v%real('height', b%height, unit='[length]', range='> 0', doc='extent in y')
      call v%int('nx', b%nx, range='>= 1', doc='cells along x')
      call v%int('ny', b%ny, range='>= 1', doc='cells along y')
      if (form == ALL_FORMS .or. NDIM == 3) then
        call v%real('z0', b%z0, unit='[length]', doc='a box (3D deck): z of its front side')
        call v%real('depth', b%depth, unit='[length]', range='> 0', doc='a box (3D deck): extent in '// &
          'z; giving it makes the deck 3D (unless `&scene dimension=2`, then it is bad input). Not '// &
          'given in a 2D deck')
        call v%int('nz', b%nz, range='>= 1', doc='a box (3D deck): cells along z')
      end if
      call v%enum('element', b%element, ELEMENT_CHOICES, doc='`''Q1''`: bilinear quadrilaterals '// &
        '(2x2 Gauss); `''P1''`: linear triangles, each cell split along its lower-left/upper-right '// &
        'diagonal. A box: `''Q1''` trilinear hexahedra (2x2x2 Gauss), `''P1''` linear tetrahedra, each '// &
        'cell split into six around its diagonal from the lowest to the highest corner')
    end if
    if (form == ALL_FORMS .or. len_trim(b%material) > 0) then
      call v%str('material', b%material, doc='the name of a `&material`: the body is made of it '// &
        '(its cells outside every `&region`); give `material` or `young`, `poisson`, `density`, '// &
        'not both. Rendered only when given')
    end if
    if (form == ALL_FORMS .or. b%angle /= 0.0_wp) call v%real('angle', b%angle, unit='[degrees]', &
      doc='the direction of the material''s axis 1 (orthotropic and anisotropic materials), from x '// &
      'counter-clockwise. Rendered only when not 0')
    if (form == ALL_FORMS .or. len_trim(b%material) == 0) then
      call v%real('young', b%young, unit='[stress]', range=MODULUS_RANGE, doc='Young''s modulus of the '// &
        'body''s isotropic material (without `material`)')
      call v%real('poisson', b%poisson, unit='[-]', range='-1 < poisson < 0.5', doc='Poisson''s '// &
        'ratio; 0.5 (an incompressible material) is rejected: this displacement formulation '// &
        'cannot model it')
      call v%real('density', b%density, unit='[mass/length^3]', range='>= 0', doc='mass per '// &
        'volume, for `&body_force gravity`; mass in force x time^2 / length: kg with SI units, '// &
        'tonnes with mm-N-MPa (steel: 7850 and 7.85e-9)')
    end if
    if (form /= GROUP_FORM) then
      call v%enum('left', b%bc(SIDE_LEFT), BC_CHOICES, base=BC_FREE, doc='condition on the side '// &
        'x = x0: `''free''` (traction-free unless a `&traction` loads it), `''clamped''` (u = 0), '// &
        '`''roller''` (normal displacement 0), `''contact''` (two-body form of `&contact`: '// &
        'exactly one side per body, paired with the other body''s contact side by dual mortar), '// &
        '`''displacement''` (given by '// &
        'a `&displacement`)')
      call v%enum('right', b%bc(SIDE_RIGHT), BC_CHOICES, base=BC_FREE, doc='condition on the '// &
        'side x = x0 + width, as `left`')
      call v%enum('top', b%bc(SIDE_TOP), BC_CHOICES, base=BC_FREE, doc='condition on the side '// &
        'y = y0 + height, as `left`')
      call v%enum('bottom', b%bc(SIDE_BOTTOM), BC_CHOICES, base=BC_FREE, doc='condition on the '// &
        'side y = y0, as `left`')
      if (form == ALL_FORMS .or. NDIM == 3) then
        call v%enum('front', b%bc(SIDE_FRONT), BC_CHOICES, base=BC_FREE, doc='a box: condition on '// &
          'the side z = z0, as `left`')
        call v%enum('back', b%bc(SIDE_BACK), BC_CHOICES, base=BC_FREE, doc='a box: condition on '// &
          'the side z = z0 + depth, as `left`')
      end if
    end if
  end subroutine body_vars

  !> &traction: on a side (t0, t1) or on a group (t0, tx, ty, pressure).
  subroutine traction_vars(t, v, form)
    type(load_in_t), target, intent(inout) :: t
    type(vars_t), intent(out) :: v
    integer, intent(in) :: form
    call v%int('body', t%body, range='1 to N', required=.true., doc='the body loaded')
    if (form /= GROUP_FORM) call v%enum('side', t%side, SIDE_CHOICES, doc='the side of the '// &
      'rectangle loaded (not its contact side)')
    if (form /= SIDE_FORM) call v%str('group', t%group, doc='the edge group loaded: a physical '// &
      'curve of the body''s mesh (3D: a physical surface; a rectangle has `''left''`, `''right''`, '// &
      '`''bottom''`, `''top''`)')
    call v%pair('t0', t%t0(1:NCOMP), unit='[stress]', doc='the constant part of the traction vector '// &
      '(x, y; in a 3D deck x, y, z)')
    if (form /= GROUP_FORM .and. (form == ALL_FORMS .or. NDIM == 2)) call v%pair('t1', t%t1(1:2), &
      unit='[stress/length]', doc='plane only: its rate along '// &
      'the side: t(s) = t0 + t1*s, s the global coordinate along the side (x on top and bottom, '// &
      'y on left and right)')
    if (form /= SIDE_FORM .and. (form == ALL_FORMS .or. NDIM == 2)) then
      call v%pair('tx', t%tx(1:2), unit='[stress/length]', doc='plane only: its rate along x: t(x,y) = '// &
        't0 + tx*x + ty*y - pressure*n')
      call v%pair('ty', t%ty(1:2), unit='[stress/length]', doc='plane only: its rate along y')
    end if
    if (form /= SIDE_FORM) then
      call v%real('pressure', t%pressure, unit='[stress]', doc='a normal pressure, positive '// &
        'pushing into the body (n is the outward unit normal of each edge)')
    end if
    if (form == ALL_FORMS .or. t%stage /= 1) call v%int('stage', t%stage, range='>= 1', doc=STAGE_DOC)
  end subroutine traction_vars

  !> &boundary: prescribed components on a group; read with every component (ALL_FORMS),
  !! rendered (GIVEN_FORM) with the components given (t%fix).
  subroutine boundary_vars(t, v, form)
    type(load_in_t), target, intent(inout) :: t
    type(vars_t), intent(out) :: v
    integer, intent(in) :: form
    call v%int('body', t%body, range='1 to N', required=.true., doc='the body')
    call v%str('group', t%group, required=.true., doc='the group: a physical curve or point of '// &
      'the body''s mesh (3D: a physical surface, curve or point), or a rectangle''s side '// &
      '(`''left''`, `''right''`, `''bottom''`, `''top''`; a box''s also `''front''`, `''back''`)')
    if (form == ALL_FORMS .or. t%fix(1)) call v%real('ux', t%ux, unit='[length]', doc='the x '// &
      'displacement of every node of the group; not given: free')
    if (form == ALL_FORMS .or. t%fix(2)) call v%real('uy', t%uy, unit='[length]', doc='the y '// &
      'displacement of every node of the group; not given: free')
    if (form == ALL_FORMS .or. t%fix(3)) call v%real('uz', t%uz, unit='[length]', doc='3D deck: the '// &
      'z displacement of every node of the group; not given: free')
    if (form == ALL_FORMS .or. t%stage /= 1) call v%int('stage', t%stage, range='>= 1', doc=STAGE_DOC// &
      '. A zero displacement (a support) is no load: it holds in every stage')
  end subroutine boundary_vars

  !> &body_force: every variable (reading and rendering alike).
  subroutine body_force_vars(f, v)
    type(body_force_cfg_t), target, intent(inout) :: f
    type(vars_t), intent(out) :: v
    call v%int('body', f%body, range='0 to N', doc='the body it acts on; 0: every body')
    call v%pair('gravity', f%gravity(1:NCOMP), unit='[length/time^2]', doc='an acceleration field: each '// &
      'body it acts on carries density x gravity per volume (its `density` > 0); SI: '// &
      '`0.0, -9.81`, mm-N-MPa: `0.0, -9810.0`')
    call v%pair('force', f%force(1:NCOMP), unit='[force/length^3]', doc='a force per volume, whatever '// &
      'the density; added to the gravity''s')
    call v%int('stage', f%stage, range='>= 1', doc=STAGE_DOC)
  end subroutine body_force_vars

  !> &material: every variable for reading; rendering (`rendering`) the ones given.
  subroutine material_vars(m, v, rendering)
    type(material_cfg_t), target, intent(inout) :: m
    type(vars_t), intent(out) :: v
    logical, intent(in), optional :: rendering
    logical :: all_vars
    all_vars = .true.
    if (present(rendering)) all_vars = .not. rendering
    call v%str('name', m%name, required=.true., doc='the material''s name, by which `&body` and '// &
      '`&region` use it; each name once')
    call opt('young', m%young, '[stress]', MODULUS_RANGE, 'isotropic: Young''s modulus')
    call opt('poisson', m%poisson, '[-]', '-1 < poisson < 0.5', 'isotropic: Poisson''s ratio')
    call opt('e1', m%e1, '[stress]', MODULUS_RANGE, 'orthotropic: the modulus along the material''s axis '// &
      '1 (in the plane, at the body''s or region''s `angle` from x)')
    call opt('e2', m%e2, '[stress]', MODULUS_RANGE, 'orthotropic: the modulus along axis 2 (in the plane)')
    call opt('e3', m%e3, '[stress]', MODULUS_RANGE, 'orthotropic: the modulus along axis 3 (out of the '// &
      'plane); plane strain only')
    call opt('nu12', m%nu12, '[-]', '', 'orthotropic: the contraction along 2 under a stress '// &
      'along 1 (nu12/e1 = nu21/e2); the Poisson''s ratios must leave the compliance positive '// &
      'definite (nu12^2 < e1/e2, ...)')
    call opt('nu13', m%nu13, '[-]', '', 'orthotropic: the contraction along 3 under a stress '// &
      'along 1; plane strain only')
    call opt('nu23', m%nu23, '[-]', '', 'orthotropic: the contraction along 3 under a stress '// &
      'along 2; plane strain only')
    call opt('g12', m%g12, '[stress]', MODULUS_RANGE, 'orthotropic: the in-plane shear modulus')
    call opt('c11', m%c11, '[stress]', '', 'anisotropic: the stiffness in Voigt order 1 = xx, '// &
      '2 = yy, 3 = zz, 6 = xy of the material axes: sxx = c11 exx + c12 eyy + c13 ezz + c16 gxy, '// &
      '...; it must be positive definite, each constant within +-1.341e148 (double precision)')
    call opt('c12', m%c12, '[stress]', '', 'anisotropic: xx-yy')
    call opt('c16', m%c16, '[stress]', '', 'anisotropic: xx-xy; not given: 0')
    call opt('c22', m%c22, '[stress]', '', 'anisotropic: yy-yy')
    call opt('c26', m%c26, '[stress]', '', 'anisotropic: yy-xy; not given: 0')
    call opt('c66', m%c66, '[stress]', '', 'anisotropic: xy-xy')
    call opt('c13', m%c13, '[stress]', '', 'anisotropic: xx-zz; plane strain needs c13 and c23; '// &
      'in plane stress c13, c23, c33 are given together (ezz condensed out) or not at all (c11 '// &
      'to c66 are then the plane-stress stiffness)')
    call opt('c23', m%c23, '[stress]', '', 'anisotropic: yy-zz')
    call opt('c36', m%c36, '[stress]', '', 'anisotropic: zz-xy; not given: 0')
    call opt('c33', m%c33, '[stress]', '', 'anisotropic: zz-zz')
    if (all_vars .or. m%density /= 0.0_wp) call v%real('density', m%density, unit='[mass/length^3]', &
      range='>= 0', doc='mass per volume, for `&body_force gravity` (as `&body density`). '// &
      'Rendered only when not 0')
  contains
    subroutine opt(name, x, unit, range, doc)
      character(len=*), intent(in) :: name, unit, range, doc
      real(wp), target, intent(inout) :: x
      if (all_vars .or. x /= UNSET) call v%real(name, x, unit=unit, range=range, doc=doc)
    end subroutine opt
  end subroutine material_vars

  !> &region: every variable (reading and rendering alike).
  subroutine region_vars(r, v)
    type(region_cfg_t), target, intent(inout) :: r
    type(vars_t), intent(out) :: v
    call v%int('body', r%body, range='1 to N', required=.true., doc='the body, from a mesh file')
    call v%str('name', r%name, required=.true., doc='a physical surface of the body''s mesh file '// &
      'whose cells (those of the body) are this region; each region of a body once')
    call v%str('material', r%material, required=.true., doc='the name of the `&material` the '// &
      'region is made of')
    call v%real('angle', r%angle, unit='[degrees]', doc='the direction of the material''s axis 1 in '// &
      'the region, from x counter-clockwise')
  end subroutine region_vars

  !> &displacement: `form` ALL_FORMS reads every variable, SIDE_FORM renders one.
  subroutine displacement_vars(t, v, form)
    type(load_in_t), target, intent(inout) :: t
    type(vars_t), intent(out) :: v
    integer, intent(in) :: form
    call v%int('body', t%body, range='1 to N', required=.true., doc='the body')
    call v%enum('side', t%side, SIDE_CHOICES, required=.true., doc='the side, declared '// &
      '`''displacement''` in the body''s `&body`')
    call v%pair('u', t%u(1:NCOMP), unit='[length]', doc='the displacement vector of every node of the side')
    if (form == ALL_FORMS .or. t%stage /= 1) call v%int('stage', t%stage, range='>= 1', doc=STAGE_DOC// &
      '. A zero displacement (a support) is no load: it holds in every stage')
  end subroutine displacement_vars

  !> &contact: `form` ALL_FORMS reads every variable; TWO_BODY_FORM renders the pair of
  !! bodies 1 and 2 (body1_group, body2_group), PAIR_FORM a pair named by its bodies.
  subroutine contact_vars(c, v, form)
    type(contact_cfg_t), target, intent(inout) :: c
    type(vars_t), intent(out) :: v
    integer, intent(in) :: form
    if (form /= TWO_BODY_FORM) then
      call v%ints('bodies', c%bodies, range='two different ids, 1 to N', required=.true., &
        doc='the two bodies of the pair, `bodies=A,B`')
      call v%strs('groups', c%body_group, required=.true., doc='the contact surface of each, '// &
        'in the order of `bodies`: an edge group of its mesh, or a rectangle''s side (`''left''`, '// &
        '`''right''`, `''bottom''`, `''top''`); a group of a body is in at most one pair with each '// &
        'other body (a lid on two blocks: its bottom in a pair with each)')
    end if
    if (form /= PAIR_FORM) then
      call v%str('body1_group', c%body_group(1), doc='body 1''s contact surface as an edge group '// &
        '(give both groups or neither); `''''`: the side its `&body` declares `''contact''`')
      call v%str('body2_group', c%body_group(2), doc='body 2''s contact surface, as `body1_group`')
    end if
    call v%int('slave', c%slave, range='0 or a body of the pair', doc='the body whose contact '// &
      'nodes carry the multipliers (mortar); 0: the one whose contact group has the shorter mean '// &
      'edge (the finer), the one with the smaller id on a tie')
    call v%real('gap_radius', c%gap_radius, unit='[length]', range='>= 0', doc='0: no initial '// &
      'gap; R > 0: an initial normal gap g0(s) = (s - gap_center)^2/(2R) on top of the '// &
      'geometry''s (with groups: s is the slave node''s x)')
    call v%real('gap_center', c%gap_center, unit='[length]', doc='s of the vertex of that parabola')
    call v%enum('friction', c%friction, FRICTION_CHOICES, doc='`''none''` (frictionless), '// &
      '`''tresca''` (the shear traction bounded by `slip_bound`: |t| <= slip_bound) or `''coulomb''` '// &
      '(|t| <= mu p, p the contact pressure); `mu=0` or `slip_bound=0` is frictionless; in a 3D deck t is '// &
      'the shear vector in the tangent plane and |t| its length')
    call v%real('mu', c%mu, unit='[-]', range='0 <= mu <= 1e4; with `friction=''coulomb''` only', &
      doc='*coulomb only:* the friction coefficient')
    call v%real('slip_bound', c%slip_bound, unit='[stress]', range='0 <= slip_bound <= 1e20; with '// &
      '`friction=''tresca''` only', &
      doc='*tresca only:* the bound of the shear traction')
    call v%enum('overlap', c%overlap, OVERLAP_CHOICES, doc='what an overlap of the two groups in the '// &
      'initial configuration is: `''refuse''` (bad input beyond a thousandth of the slave''s mean '// &
      'edge, below it taken as contact) or `''interference''` (a fit: the bodies are pressed apart '// &
      'by the overlap; up to 1% of the slave group''s extent, a small strain)')
    if (form == ALL_FORMS .or. c%interference_stage /= 0) call v%int('interference_stage', &
      c%interference_stage, range='>= 0; > 0 with `overlap=''interference''` only', doc='*interference '// &
      'only:* 0: the whole overlap in every load step (a fit solved at once); s >= 1: the overlap '// &
      'ramped over the load steps of stage s as a load is (none in the stages before, whole in '// &
      'those after), a fit pressed together step by step. Rendered only when not 0')
  end subroutine contact_vars

  !> &solver; `rendering`: load_steps only when not its default.
  subroutine solver_vars(s, v, rendering)
    type(solver_cfg_t), target, intent(inout) :: s
    type(vars_t), intent(out) :: v
    logical, intent(in), optional :: rendering
    logical :: all_vars
    all_vars = .true.
    if (present(rendering)) all_vars = .not. rendering
    call v%enum('method', s%method, METHOD_CHOICES, doc='`''robin''`: the Robin domain '// &
      'decomposition; `''monolithic''`: the same discrete problem in one piece (MPRGP on the '// &
      'condensed interface problem), the reference')
    call v%enum('robin_operator', s%robin_operator, ROBIN_CHOICES, doc='the Robin operator: '// &
      '`''steklov''` (the paper''s: the other body''s flexibility), `''constant''` (alpha M^-1), '// &
      '`''harmonic''` (2 F1 (F1+F2)^-1 F2, robust to a stiffness contrast and to a body held '// &
      'only by contact)')
    call v%real('alpha', s%alpha, unit='[length/stress]', range='>= 0; > 0 with '// &
      '`robin_operator=''constant''`', doc='the constant Robin parameter')
    call v%real('delta', s%delta, unit='[-]', range='0 < delta <= 1', doc='relaxation of the '// &
      'outer iteration (0.5 is the best choice for `''harmonic''`, and for `''steklov''` on equal '// &
      'bodies)')
    call v%real('tol', s%tol, unit='[-]', range='> 0', doc='outer tolerance, on the criterion '// &
      'of `stop`')
    call v%enum('stop', s%stop, STOP_CHOICES, doc='`''increment''`: the paper''s relative '// &
      'increment of the obstacles; `''residual''`: the true residual of the iterate; `''auto''`: '// &
      'increment for two bodies in one pair, residual for several pairs (a slow chain of bodies has '// &
      'small increments long before a small error)')
    call v%int('max_outer', s%max_outer, range='>= 1', doc='outer iteration limit (reached: exit 2)')
    call v%enum('factorization', s%factor%factorization, FACTOR_CHOICES, doc='`''cholmod''`: '// &
      'sparse Cholesky (CHOLMOD), the interface ordered last; `''banded''`: reverse '// &
      'Cuthill-McKee and LAPACK dpbtrf; `''mumps''`: MUMPS over MPI ranks with the interface as '// &
      'Schur variables (`bin/robin_contact_mpi` only)')
    call v%enum('ordering', s%factor%ordering, ORDER_CHOICES, doc='fill-reducing ordering of '// &
      'each body for `''cholmod''`, the interface always last: `''metis''`, `''amd''` (CAMD), '// &
      '`''natural''` or `''nd''` (the program''s own: geometric nested dissection of a plane body, '// &
      'METIS on the node graph of a solid one)')
    call v%enum('acceleration', s%acceleration, ACCEL_CHOICES, doc='outer fixed-point '// &
      'acceleration: `''none''`, `''aitken''` (dynamic relaxation), `''anderson''` (mixing delta; '// &
      'history depth 5, for several pairs the number of bodies up to 64) or `''auto''`: none for two '// &
      'bodies in one pair, anderson for several pairs (a chain of bodies passes its forces one contact '// &
      'per outer iteration)')
    call v%real('inner_factor', s%inner_factor, unit='[-]', range='> 0', doc='inner tolerance = '// &
      'inner_factor x min(increment, residual) of the previous outer iteration, clamped to '// &
      '[inner_rtol_min, inner_rtol_max]')
    call v%real('inner_rtol_min', s%inner_rtol_min, unit='[-]', range='0 < inner_rtol_min < 1', &
      doc='floor of the adaptive inner tolerance')
    call v%real('inner_rtol_max', s%inner_rtol_max, unit='[-]', range='0 < inner_rtol_max < 1; '// &
      '>= inner_rtol_min', doc='ceiling of the adaptive inner tolerance')
    call v%enum('inner_solver', s%inner_solver, INNER_CHOICES, doc='the solver of every interface '// &
      'QP (each body''s subproblem, the monolithic problem): `''mprgp''` (matrix products only; its '// &
      'work grows with the square root of the QP''s condition number), `''active_set''` (the '// &
      'primal-dual active-set Newton method: a dense Cholesky factor of the free block per step, '// &
      'work independent of the conditioning; QPs of at most 4096 unknowns, larger ones by MPRGP) or '// &
      '`''auto''`: MPRGP within about the work of three factorizations, then the active-set method '// &
      'from where MPRGP stopped, and for the rest of the run on that body; a body held by its '// &
      'supports whose last solve cost MPRGP more than two active-set steps starts its next solve '// &
      'with the active-set method (one step when its contact set stays), MPRGP after a budget; '// &
      'with friction between solid bodies, a body held by its supports takes the active-set '// &
      'method along the circles from its second solve on, from the face of its last forces')
    call v%int('inner_max_it', s%inner_max_it, range='>= 1', doc='inner iteration limit per '// &
      'subproblem (MPRGP and Newton steps)')
    call v%real('monolithic_rtol', s%monolithic_rtol, unit='[-]', range='0 < monolithic_rtol < 1', &
      doc='MPRGP tolerance of `method=''monolithic''`')
    if (all_vars .or. s%load_steps(1) /= 1 .or. any(s%load_steps(2:) /= STEPS_UNSET)) &
      call v%list('load_steps', s%load_steps, STEPS_UNSET, range='1 to 10000; one value, or one per stage', &
      doc='load steps per stage: one value for every stage (`load_steps=4`) or one per stage '// &
      '(`load_steps=1,4`). Step k of a stage of N steps applies k/N of that stage''s loads and '// &
      'prescribed displacements; each step is solved in turn, warm-started from the one before; '// &
      'the result file holds every step (`/steps`) and the last one where a one-step run has it. '// &
      'Rendered only when not 1')
  end subroutine solver_vars

  subroutine output_vars(o, v)
    type(output_cfg_t), target, intent(inout) :: o
    type(vars_t), intent(out) :: v
    call v%str('file', o%file, doc='the result file (HDF5; its folders are created); `''''`: '// &
      '`results/<deck name>.h5`')
    call v%int('checkpoint_every', o%checkpoint_every, range='>= 0', doc='outer iterations '// &
      'between checkpoints to `<file>.ckpt.h5`; 0: only on SIGTERM or SIGINT')
    call v%int('progress_lines', o%progress_lines, range='>= 0', doc='at most about this many '// &
      'progress lines')
    call v%enum('xdmf', o%xdmf, XDMF_CHOICES, doc='the XDMF files beside the result: '// &
      '`''collection''`: `<stem>.xdmf` (every body and contact line, what ParaView opens) and '// &
      '`<stem>_contact.xdmf` (all lines); `''per_body''`: also `<stem>_bodyN.xdmf` per body and '// &
      '`<stem>_contactK.xdmf` per pair (one grid each, for meshio); `''auto''`: `per_body` up to '// &
      '64 bodies and pairs, `collection` above')
  end subroutine output_vars

end module deck_tables
