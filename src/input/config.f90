!> The data model of an input deck: scene, bodies, loads, contact, solver and output
!! settings, with their defaults. `deck` fills it from namelists; every later stage
!! (mesh, assembly, solvers, output) reads it and never writes it.
!!
!! Every enumeration of the deck is decoded here, once, into a named integer constant; its
!! spellings are one blank-separated list (`*_CHOICES`, in code order), used by the deck
!! reader to accept and by every writer to print it (`strings%word(list, code)`).
module config
  use kinds, only: wp
  use space, only: NCOMP
  implicit none (type, external)
  private

  public :: deck_init, pair_oriented, stage_count, stage_steps, body_force_of, body_stiffness
  public :: shape_vertices, side_axis

  !> robin_contact's version (`--version`, the deck echo, the result files)
  character(len=*), parameter, public :: program_version = '1.0.0'
  !> The longest file path (Linux PATH_MAX, its terminating NUL included); paths in a deck
  !! are held in variables of this length, and a longer one is refused with its length.
  integer, parameter, public :: PATH_LEN = 4096
  !> The range of an elastic modulus [stress] (young; a &material's moduli and stiffness
  !! constants): sqrt(huge)/1e6 and its inverse, where a body's stiffness, its flexibility
  !! and their squares in the solvers' norms stay within double precision with a margin of 1e6
  !! for the products of assembly (deck_checks refuses a modulus outside before its elastic
  !! law is computed; budget's check_load_range the stiffness of the laws).
  real(wp), parameter, public :: MODULUS_MAX = sqrt(huge(1.0_wp))/1.0e6_wp
  real(wp), parameter, public :: MODULUS_MIN = 1.0e6_wp/sqrt(huge(1.0_wp))
  !> The most load stages a deck may have (`stage=` of a load group, `&solver load_steps`).
  integer, parameter, public :: MAX_STAGES = 16
  !> The most load steps of one stage.
  integer, parameter, public :: MAX_STEPS = 10000
  !> An entry of `&solver load_steps` not given.
  integer, parameter, public :: STEPS_UNSET = -huge(1)
  integer, parameter, public :: SIDE_LEFT = 1    !< x = x0
  integer, parameter, public :: SIDE_RIGHT = 2   !< x = x0 + width
  integer, parameter, public :: SIDE_BOTTOM = 3  !< y = y0
  integer, parameter, public :: SIDE_TOP = 4     !< y = y0 + height
  integer, parameter, public :: SIDE_FRONT = 5   !< z = z0 (a box)
  integer, parameter, public :: SIDE_BACK = 6    !< z = z0 + depth (a box)
  integer, parameter, public :: MAX_SIDES = 6    !< sides of a box; a rectangle has the first 4
  character(len=6), parameter, public :: side_names(MAX_SIDES) = ['left  ', 'right ', 'bottom', 'top   ', &
                                                                  'front ', 'back  ']

  integer, parameter, public :: BC_FREE = 0          !< traction-free (unless a &traction says otherwise)
  integer, parameter, public :: BC_CLAMPED = 1       !< u = 0
  integer, parameter, public :: BC_ROLLER = 2        !< normal displacement 0, tangential free
  integer, parameter, public :: BC_CONTACT = 3       !< contact side (Signorini with the other body)
  integer, parameter, public :: BC_DISPLACEMENT = 4  !< prescribed displacement vector (&displacement)
  character(len=12), parameter, public :: bc_names(0:4) = &
    ['free        ', 'clamped     ', 'roller      ', 'contact     ', 'displacement']

  integer, parameter, public :: ELEM_Q1 = 1  !< bilinear quadrilateral, 2x2 Gauss
  integer, parameter, public :: ELEM_P1 = 2  !< linear triangle, each cell split in two
  integer, parameter, public :: ELEM_MIXED = 3  !< a mesh file's mix of cells (Q1 and P1, or HEX8 and TET4)
  integer, parameter, public :: ELEM_HEX8 = 4   !< trilinear hexahedron, 2x2x2 Gauss (a box's 'Q1')
  integer, parameter, public :: ELEM_TET4 = 5   !< linear tetrahedron (a box's 'P1': each cell split in six)
  integer, parameter, public :: NSHAPE = 5      !< the codes above: the cell shapes and the mixed mesh
  character(len=5), parameter, public :: element_names(NSHAPE) = ['Q1   ', 'P1   ', 'mixed', 'HEX8 ', 'TET4 ']

  integer, parameter, public :: METHOD_ROBIN = 1        !< Robin domain decomposition
  integer, parameter, public :: METHOD_MONOLITHIC = 2   !< the monolithic reference
  character(len=*), parameter, public :: METHOD_CHOICES = 'robin monolithic'

  integer, parameter, public :: INNER_AUTO = 1        !< MPRGP within a budget, then the active-set Newton method
  integer, parameter, public :: INNER_MPRGP = 2       !< MPRGP alone
  integer, parameter, public :: INNER_ACTIVE_SET = 3  !< the active-set Newton method alone
  character(len=*), parameter, public :: INNER_CHOICES = 'auto mprgp active_set'

  integer, parameter, public :: FRICTION_NONE = 1      !< frictionless
  integer, parameter, public :: FRICTION_TRESCA = 2    !< given slip bound |t| <= slip_bound
  integer, parameter, public :: FRICTION_COULOMB = 3   !< |t| <= mu p
  character(len=*), parameter, public :: FRICTION_CHOICES = 'none tresca coulomb'
  integer, parameter, public :: OVERLAP_REFUSE = 1        !< an initial overlap is bad input
  integer, parameter, public :: OVERLAP_INTERFERENCE = 2  !< an initial overlap is an interference fit
  character(len=*), parameter, public :: OVERLAP_CHOICES = 'refuse interference'

  integer, parameter, public :: ROBIN_STEKLOV = 1    !< the paper's operator: the other body's flexibility
  integer, parameter, public :: ROBIN_CONSTANT = 2   !< alpha M^-1 (constant Robin parameter)
  integer, parameter, public :: ROBIN_HARMONIC = 3   !< 2 F_1 (F_1+F_2)^-1 F_2, contrast-robust
  character(len=*), parameter, public :: ROBIN_CHOICES = 'steklov constant harmonic'

  integer, parameter, public :: STOP_INCREMENT = 1   !< the paper's relative increment of the obstacles
  integer, parameter, public :: STOP_RESIDUAL = 2    !< the true residual of the iterate
  integer, parameter, public :: STOP_AUTO = 3        !< increment for one pair, residual for several (resolved by the deck)
  character(len=*), parameter, public :: STOP_CHOICES = 'increment residual auto'

  integer, parameter, public :: FACTOR_CHOLMOD = 1   !< sparse Cholesky (SuiteSparse CHOLMOD)
  integer, parameter, public :: FACTOR_BANDED = 2    !< banded Cholesky (RCM + LAPACK dpbtrf)
  integer, parameter, public :: FACTOR_MUMPS = 3     !< MUMPS over MPI ranks, interface as Schur variables (bin/robin_contact_mpi)
  character(len=*), parameter, public :: FACTOR_CHOICES = 'cholmod banded mumps'

  integer, parameter, public :: ORDER_METIS = 1      !< CHOLMOD with METIS nested dissection
  integer, parameter, public :: ORDER_AMD = 2        !< CHOLMOD with AMD
  integer, parameter, public :: ORDER_NATURAL = 3    !< CHOLMOD in the natural order
  integer, parameter, public :: ORDER_ND = 4         !< our geometric nested dissection
  character(len=*), parameter, public :: ORDER_CHOICES = 'metis amd natural nd'

  integer, parameter, public :: ACCEL_NONE = 1       !< plain relaxation
  integer, parameter, public :: ACCEL_AITKEN = 2     !< Aitken (Irons-Tuck) dynamic relaxation
  integer, parameter, public :: ACCEL_ANDERSON = 3   !< Anderson mixing
  integer, parameter, public :: ACCEL_AUTO = 4       !< none for one pair, anderson for several (resolved by the deck)
  character(len=*), parameter, public :: ACCEL_CHOICES = 'none aitken anderson auto'

  character(len=*), parameter, public :: SIDE_CHOICES = 'left right bottom top front back'  !< SIDE_* order
  character(len=*), parameter, public :: BC_CHOICES = 'free clamped roller contact displacement'  !< BC_* order, from 0
  character(len=*), parameter, public :: ELEMENT_CHOICES = 'Q1 P1'                    !< ELEM_* order
  character(len=*), parameter, public :: PLANE_CHOICES = 'strain stress axisymmetric'

  !> The XDMF files beside a result: the collection alone (every body and contact line in
  !! `<stem>.xdmf`, all lines in `<stem>_contact.xdmf`), or also one per body and one per pair
  !! (meshio reads one grid per file); auto: those too up to XDMF_PER_BODY_MAX bodies and pairs
  integer, parameter, public :: XDMF_AUTO = 1
  integer, parameter, public :: XDMF_PER_BODY = 2
  integer, parameter, public :: XDMF_COLLECTION = 3
  character(len=*), parameter, public :: XDMF_CHOICES = 'auto per_body collection'
  integer, parameter, public :: XDMF_PER_BODY_MAX = 64

  integer, parameter, public :: UNITS_SI = 1       !< m, N, Pa
  integer, parameter, public :: UNITS_MM = 2       !< mm, N, MPa (consistent: N/mm^2 = MPa)
  integer, parameter, public :: UNITS_CUSTOM = 3   !< names given by length_unit, force_unit, stress_unit
  character(len=*), parameter, public :: UNITS_CHOICES = 'SI mm-N-MPa custom'

  !> The units the deck's numbers are in. The solver is unit-free (any consistent set works);
  !! the names label the result file's datasets, the plots and the summary lines.
  type, public :: units_cfg_t
    integer :: system = UNITS_SI                    !< UNITS_*
    character(len=16) :: length = 'm'               !< length unit name
    character(len=16) :: force = 'N'                !< force unit name
    character(len=16) :: stress = 'Pa'             !< stress unit name (force/length^2)
  end type units_cfg_t

  integer, parameter, public :: MAT_ISOTROPIC = 1     !< young, poisson
  integer, parameter, public :: MAT_ORTHOTROPIC = 2   !< e1, e2, e3, nu12, nu13, nu23, g12 in the material axes
  integer, parameter, public :: MAT_ANISOTROPIC = 3   !< the stiffness constants c11 .. c66 in the material axes
  character(len=*), parameter, public :: MAT_KIND_NAMES = 'isotropic orthotropic anisotropic'
  !> Not given (a constant of a &material that its kind does not need, or left out).
  real(wp), parameter, public :: UNSET = -huge(1.0_wp)

  !> A named material (&material): its kind follows from the constants given. Orthotropic:
  !! engineering constants of the material axes 1, 2 (in the plane, axis 1 at the body's or
  !! region's `angle` from x) and 3 (out of the plane); anisotropic: the 3D stiffness in Voigt
  !! order 1 = xx, 2 = yy, 3 = zz, 6 = xy of the material axes, z a plane of symmetry (the
  !! constants coupling yz, xz to the rest are 0). Constants not given are UNSET.
  type, public :: material_cfg_t
    character(len=64) :: name = ''
    integer :: kind = 0                     !< MAT_*, 0: not known yet
    real(wp) :: young = UNSET, poisson = UNSET                     !< isotropic [stress], [-]
    real(wp) :: e1 = UNSET, e2 = UNSET, e3 = UNSET                 !< orthotropic moduli [stress]
    real(wp) :: nu12 = UNSET, nu13 = UNSET, nu23 = UNSET, g12 = UNSET   !< [-], [stress]
    real(wp) :: c11 = UNSET, c12 = UNSET, c16 = UNSET, c22 = UNSET, c26 = UNSET, c66 = UNSET  !< [stress]
    real(wp) :: c13 = UNSET, c23 = UNSET, c36 = UNSET, c33 = UNSET  !< out of the plane [stress]
    real(wp) :: density = 0.0_wp            !< mass per volume [mass/length^3]
    character(len=64) :: origin = ''        !< where the deck gave it ('line N', ...)
  end type material_cfg_t

  !> A part of a body from a mesh file, its cells those of a physical surface, made of a
  !! material of its own (&region).
  type, public :: region_cfg_t
    integer :: body = 0                     !< body id
    character(len=128) :: name = ''         !< the physical surface
    character(len=64) :: material = ''      !< the material's name
    real(wp) :: angle = 0.0_wp              !< material axis 1 from x [degrees]
    character(len=64) :: origin = ''        !< where the deck gave it
  end type region_cfg_t

  !> The elastic law of a body or of one of its regions, for the scene's plane model, resolved
  !! from the deck (deck_cross): stress (sxx, syy, sxy, szz) = d (exx, eyy, gxy, ezz); plane
  !! strain: ezz = 0 (column 4 unused); plane stress: szz = 0 (row and column 4 are 0).
  type, public :: elastic_law_t
    character(len=128) :: region = ''       !< the physical surface of its cells ('': the body's own)
    logical :: isotropic = .true.           !< then lame_lambda, lame_mu give d
    real(wp) :: lame_lambda = 0.0_wp        !< (effective) first Lame parameter [stress]
    real(wp) :: lame_mu = 0.0_wp            !< shear modulus [stress]
    real(wp) :: d(4, 4) = 0.0_wp            !< the stiffness [stress]
    real(wp) :: density = 0.0_wp            !< mass per volume [mass/length^3]
  end type elastic_law_t

  !> One elastic body: a rectangle meshed by nx x ny cells, or the cells of a Gmsh file.
  type, public :: body_cfg_t
    integer :: id = 0                 !< 1 .. nbody
    character(len=PATH_LEN) :: mesh = ''   !< Gmsh MSH 4.1 file ('' : the rectangle below); absolute after reading
    character(len=128) :: region = '' !< physical surface of the file that is this body ('' : the only one)
    real(wp) :: x0 = 0.0_wp           !< lower-left corner x [length]
    real(wp) :: y0 = 0.0_wp           !< lower-left corner y [length]
    real(wp) :: width = 1.0_wp        !< extent in x [length]
    real(wp) :: height = 1.0_wp       !< extent in y [length]
    real(wp) :: z0 = 0.0_wp           !< a box's front z [length]
    real(wp) :: depth = UNSET         !< a box's extent in z [length] (UNSET: not given; given: a box)
    integer :: nx = 8                 !< cells along x
    integer :: ny = 8                 !< cells along y
    integer :: nz = 8                 !< a box's cells along z
    integer :: element = ELEM_Q1      !< ELEM_Q1 or ELEM_P1 (a box: hexahedra or tetrahedra)
    real(wp) :: young = 2.1e11_wp     !< Young's modulus [stress]
    real(wp) :: poisson = 0.3_wp      !< Poisson's ratio [-], in (-1, 0.5)
    real(wp) :: density = 0.0_wp      !< mass per volume [mass/length^3] (&body_force gravity)
    character(len=64) :: material = ''  !< a &material's name ('': young, poisson, density above)
    real(wp) :: angle = 0.0_wp        !< the material's axis 1 from x [degrees]
    integer :: bc(MAX_SIDES) = BC_FREE        !< condition per side (SIDE_* order; a rectangle's first 4)
    !> prescribed displacement per side when bc = BC_DISPLACEMENT (NCOMP components) [length]
    real(wp) :: u_side(3, MAX_SIDES) = 0.0_wp
    integer :: side_stage(MAX_SIDES) = 1      !< load stage of each side's prescribed displacement
    !> its elastic laws, resolved from the deck: law(1) its own material, then one per &region
    !! of the body in deck order (unallocated: young and poisson, isotropic)
    type(elastic_law_t), allocatable :: law(:)
  end type body_cfg_t

  !> A traction on one side of a rectangle, t(s) = t0 + t1*s with s the global coordinate
  !! along the side (x on top/bottom, y on left/right); or on a named edge group of a body
  !! (group /= ''), t(x,y) = t0 + tx*x + ty*y - pressure*n with n the outward normal.
  type, public :: traction_cfg_t
    integer :: body = 0               !< body id
    integer :: side = 0               !< SIDE_* (0 with a group)
    character(len=128) :: group = ''  !< edge group name ('' : the side)
    real(wp) :: t0(3) = 0.0_wp        !< [stress] (NCOMP components used)
    real(wp) :: t1(3) = 0.0_wp        !< [stress/length] (side; plane only)
    real(wp) :: tx(3) = 0.0_wp        !< d t / d x [stress/length] (group; plane only)
    real(wp) :: ty(3) = 0.0_wp        !< d t / d y [stress/length] (group; plane only)
    real(wp) :: pressure = 0.0_wp     !< normal pressure, positive pushing in [stress] (group)
    integer :: stage = 1              !< the load stage that ramps it
    character(len=64) :: origin = ''  !< where the deck gave it ('line N', 'command-line override k')
  end type traction_cfg_t

  !> A body force (&body_force): on one body or on every body (body = 0), the force per
  !! volume density x gravity + force, constant over the body, ramped by its stage.
  type, public :: body_force_cfg_t
    integer :: body = 0               !< body id, 0: every body
    real(wp) :: gravity(3) = 0.0_wp   !< acceleration [length/time^2] (times each body's density; NCOMP used)
    real(wp) :: force(3) = 0.0_wp     !< force per volume [force/length^3]
    integer :: stage = 1              !< the load stage that ramps it
    character(len=64) :: origin = ''  !< where the deck gave it
  end type body_force_cfg_t

  !> Prescribed displacement components on a named edge group (&boundary).
  type, public :: boundary_cfg_t
    integer :: body = 0               !< body id
    character(len=128) :: group = ''  !< edge group name
    logical :: fix(3) = .false.       !< which components are prescribed (ux, uy, uz; NCOMP used)
    real(wp) :: u(3) = 0.0_wp         !< their values [length]
    integer :: stage = 1              !< the load stage that ramps nonzero values
    character(len=64) :: origin = ''  !< where the deck gave it
  end type boundary_cfg_t

  !> How each body's stiffness is factorized (what the condensation stage needs).
  type, public :: factor_cfg_t
    integer :: factorization = FACTOR_CHOLMOD         !< FACTOR_*
    integer :: ordering = ORDER_ND                    !< ORDER_* (cholmod only)
  end type factor_cfg_t

  !> One contact pair: two bodies, the contact surface of each (a named edge group, or ''
  !! for a rectangle's side declared 'contact'), paired by mortar, and an initial gap on top
  !! of the geometry's.
  type, public :: contact_cfg_t
    integer :: bodies(2) = [1, 2]                     !< the two body ids, in the order given
    character(len=128) :: body_group(2) = ''          !< contact edge group of each ('' : the 'contact' side)
    integer :: slave = 0                              !< mortar slave: a body id of the pair, 0: the finer surface
    real(wp) :: gap_radius = 0.0_wp                   !< R of the parabolic initial gap, 0: none [length]
    real(wp) :: gap_center = 0.0_wp                   !< xc of the parabolic gap [length]
    integer :: friction = FRICTION_NONE               !< FRICTION_*
    real(wp) :: mu = 0.0_wp                           !< Coulomb coefficient [-]
    real(wp) :: slip_bound = 0.0_wp                   !< Tresca's bound on the shear traction [stress]
    integer :: overlap = OVERLAP_REFUSE               !< OVERLAP_*: what an initial overlap of the groups is
    !> an interference fit's stage: 0 the whole overlap at every step; s >= 1 ramped over stage
    !! s's load steps as a load (none before it, whole after it)
    integer :: interference_stage = 0
  end type contact_cfg_t

  !> Outer and inner solver settings (what the contact stage needs, and the factorization).
  type, public :: solver_cfg_t
    integer :: method = METHOD_ROBIN                  !< METHOD_*
    integer :: robin_operator = ROBIN_HARMONIC        !< ROBIN_* (harmonic: robust to material contrast)
    real(wp) :: alpha = 0.0_wp                        !< constant Robin parameter [length/stress]
    real(wp) :: delta = 0.5_wp                        !< relaxation, 0 < delta <= 1
    real(wp) :: tol = 1.0e-8_wp                       !< outer tolerance
    integer :: stop = STOP_AUTO                       !< STOP_* (AUTO is resolved when the deck is read)
    integer :: max_outer = 800                        !< outer iteration limit
    type(factor_cfg_t) :: factor                      !< factorization and ordering
    integer :: acceleration = ACCEL_AUTO              !< ACCEL_* (AUTO is resolved when the deck is read)
    real(wp) :: inner_factor = 1.0e-3_wp              !< inner rtol = inner_factor * outer progress (clamped)
    real(wp) :: inner_rtol_min = 1.0e-12_wp           !< floor of the adaptive inner tolerance
    real(wp) :: inner_rtol_max = 1.0e-2_wp            !< ceiling of the adaptive inner tolerance
    integer :: inner_solver = INNER_AUTO              !< INNER_*: the solver of the interface QPs
    integer :: inner_max_it = 100000                  !< MPRGP iteration limit per subproblem
    real(wp) :: monolithic_rtol = 1.0e-12_wp          !< MPRGP tolerance for method='monolithic'
    !> load steps per stage: one value for every stage, or one per stage (STEPS_UNSET: not given)
    integer :: load_steps(MAX_STAGES) = reshape([1], [MAX_STAGES], pad=[STEPS_UNSET])
  end type solver_cfg_t

  !> Output settings.
  type, public :: output_cfg_t
    character(len=PATH_LEN) :: file = ''              !< result file ('' -> results/<deck name>.h5)
    integer :: checkpoint_every = 0                   !< outer iterations between checkpoints (0: none)
    integer :: progress_lines = 30                    !< at most about this many progress lines
    integer :: xdmf = XDMF_AUTO                       !< XDMF_*: which XDMF files beside the result
  end type output_cfg_t

  !> A whole input deck, defaults included.
  type, public :: deck_t
    character(len=PATH_LEN) :: source = ''            !< deck path as given
    character(len=256) :: title = ''                  !< free text
    !> the scene's dimension: 2 (plane or axisymmetric bodies) or 3 (solid bodies); 0 until
    !! resolved (&scene dimension, or 3 where a body gives a depth)
    integer :: dimension = 0
    logical :: plane_strain = .true.                  !< .true.: plane strain (or axisymmetric), .false.: plane stress
    !> bodies of revolution about the y axis, x = r >= 0: every integral per radian, with the
    !! hoop strain (plane_strain is .true.: the laws have the out-of-plane, here hoop, row)
    logical :: axisymmetric = .false.
    type(units_cfg_t) :: units                        !< unit names (&scene units=...)
    integer :: nbody = 0                              !< number of bodies
    type(body_cfg_t), allocatable :: body(:)          !< the bodies, indexed by id (1 .. nbody)
    integer :: ntraction = 0                          !< number of tractions in use
    type(traction_cfg_t), allocatable :: traction(:)  !< tractions (size >= ntraction)
    integer :: nbody_force = 0                        !< number of &body_force groups
    type(body_force_cfg_t), allocatable :: body_force(:)  !< body forces (size >= nbody_force)
    integer :: nmaterial = 0                          !< number of &material groups
    type(material_cfg_t), allocatable :: material(:)  !< named materials (size >= nmaterial)
    integer :: nregion = 0                            !< number of &region groups
    type(region_cfg_t), allocatable :: region(:)      !< regions of bodies (size >= nregion)
    integer :: nboundary = 0                          !< number of &boundary groups
    type(boundary_cfg_t), allocatable :: boundary(:)  !< prescribed components on groups (size >= nboundary)
    integer :: npair = 0                              !< number of contact pairs
    type(contact_cfg_t), allocatable :: pair(:)       !< the contact pairs (&contact; size >= npair)
    logical :: pairs_named = .false.                  !< given as &contact bodies=A,B (else the two-body form)
    type(solver_cfg_t) :: solver
    type(output_cfg_t) :: output
    character(len=:), allocatable :: effective        !< effective deck as namelist text
  end type deck_t

contains

  !> The vertices of a cell of shape `shape` (ELEM_*): 4, 3, 8, 4; 0 for ELEM_MIXED.
  elemental integer function shape_vertices(shape)
    integer, intent(in) :: shape         !< ELEM_Q1, ELEM_P1, ELEM_HEX8 or ELEM_TET4
    select case (shape)
    case (ELEM_Q1, ELEM_TET4)
      shape_vertices = 4
    case (ELEM_P1)
      shape_vertices = 3
    case (ELEM_HEX8)
      shape_vertices = 8
    case default
      shape_vertices = 0
    end select
  end function shape_vertices

  !> The coordinate axis normal to a side (1 = x: left, right; 2 = y: bottom, top; 3 = z:
  !! front, back).
  elemental integer function side_axis(side)
    integer, intent(in) :: side          !< SIDE_*
    side_axis = (side + 1)/2
  end function side_axis

  !> A deck of `nbody` default bodies (ids 1 .. nbody) and `npair` default pairs (bodies
  !! 1 and 2, each on its 'contact' side): the start of a deck built in code.
  subroutine deck_init(d, nbody, npair)
    type(deck_t), intent(inout) :: d   !< the deck; its bodies and pairs are replaced
    integer, intent(in) :: nbody       !< number of bodies
    integer, intent(in) :: npair       !< number of pairs
    integer :: b
    if (allocated(d%body)) deallocate (d%body)
    if (allocated(d%pair)) deallocate (d%pair)
    allocate (d%body(nbody), d%pair(npair))
    d%nbody = nbody
    d%npair = npair
    do b = 1, nbody
      d%body(b)%id = b
    end do
  end subroutine deck_init

  !> The pair with its bodies in ascending order of id (groups swapped along): entry a of
  !! `body_group` is then the group of the pair's a-th smallest body.
  pure function pair_oriented(p) result(q)
    type(contact_cfg_t), intent(in) :: p   !< the pair as given
    type(contact_cfg_t) :: q
    q = p
    if (p%bodies(1) > p%bodies(2)) then
      q%bodies = p%bodies(2:1:-1)
      q%body_group = p%body_group(2:1:-1)
    end if
  end function pair_oriented

  !> Body a's body force per volume [force/length^3] in each of nstage stages (columns), for
  !! each of its elastic laws (planes; one for a body without laws): the sum of the deck's
  !! &body_force groups on it or on every body, density x gravity + force each, the density
  !! the law's.
  pure function body_force_of(d, a, nstage) result(b)
    type(deck_t), intent(in) :: d   !< the deck
    integer, intent(in) :: a        !< body id
    integer, intent(in) :: nstage   !< the deck's stages (stage_count)
    real(wp), allocatable :: b(:, :, :)
    integer :: i, k, nlaw
    nlaw = 1
    if (allocated(d%body(a)%law)) nlaw = size(d%body(a)%law)
    allocate (b(NCOMP, nstage, nlaw))
    b = 0.0_wp
    do k = 1, nlaw
      do i = 1, d%nbody_force
        associate (f => d%body_force(i))
          if (f%body /= 0 .and. f%body /= a) cycle
          if (allocated(d%body(a)%law)) then
            b(:, f%stage, k) = b(:, f%stage, k) + d%body(a)%law(k)%density*f%gravity(1:size(b, 1)) + &
                               f%force(1:size(b, 1))
          else
            b(:, f%stage, k) = b(:, f%stage, k) + d%body(a)%density*f%gravity(1:size(b, 1)) + f%force(1:size(b, 1))
          end if
        end associate
      end do
    end do
  end function body_force_of

  !> The density of a body's own material (its `density`, or its &material's).
  pure real(wp) function body_density(b)
    type(body_cfg_t), intent(in) :: b
    body_density = b%density
    if (allocated(b%law)) body_density = b%law(1)%density
  end function body_density

  !> The range of a body's stiffness over its laws [stress]: Young's modulus for a body of
  !! young and poisson; else the smallest diagonal entry of the plane stiffness and the
  !! largest entry of any (the scales of K's entries, for the checks of the number range).
  pure subroutine body_stiffness(b, lo, hi)
    type(body_cfg_t), intent(in) :: b   !< the body
    real(wp), intent(out) :: lo         !< the smallest [stress]
    real(wp), intent(out) :: hi         !< the largest [stress]
    integer :: k, i
    lo = b%young
    hi = b%young
    if (.not. allocated(b%law)) return
    if (len_trim(b%material) == 0 .and. size(b%law) == 1) return
    lo = huge(1.0_wp)
    hi = 0.0_wp
    do k = 1, size(b%law)
      do i = 1, 3
        lo = min(lo, b%law(k)%d(i, i))
      end do
      hi = max(hi, maxval(abs(b%law(k)%d)))
    end do
  end subroutine body_stiffness

  !> The deck's load stages: the largest `stage=` of its load groups (1 without any).
  pure integer function stage_count(d) result(n)
    type(deck_t), intent(in) :: d   !< the deck
    integer :: b
    n = 1
    if (d%ntraction > 0) n = max(n, maxval(d%traction(1:d%ntraction)%stage))
    if (d%nboundary > 0) n = max(n, maxval(d%boundary(1:d%nboundary)%stage))
    if (d%nbody_force > 0) n = max(n, maxval(d%body_force(1:d%nbody_force)%stage))
    if (d%npair > 0) n = max(n, maxval(d%pair(1:d%npair)%interference_stage))
    do b = 1, d%nbody
      n = max(n, maxval(d%body(b)%side_stage, mask=d%body(b)%bc == BC_DISPLACEMENT))
    end do
  end function stage_count

  !> The load steps of each of the nstage stages: `load_steps` per stage, or its one value
  !! for every stage.
  pure function stage_steps(solver, nstage) result(steps)
    type(solver_cfg_t), intent(in) :: solver   !< its load_steps
    integer, intent(in) :: nstage              !< the deck's stages
    integer :: steps(nstage)
    if (count(solver%load_steps /= STEPS_UNSET) <= 1) then
      steps = solver%load_steps(1)
    else
      steps = solver%load_steps(1:nstage)
    end if
  end function stage_steps

end module config
