!> The element as one type: what the assembly asks of a cell (its stiffness, its stress, the
!! integrals of its shape functions, the loads of a body force) behind one abstract type
!! `element_t`, one concrete type per kinematic model, and a factory that builds the element
!! of a cell shape and a model (`element_for`) or the table of every shape of a model
!! (`element_table`), as the Robin operators and the factorization back-ends are built.
!! The assembly never tests a shape or a model: it asks the element of the cell.
!!
!! Models: plane strain and plane stress (`plane_element_t`: x, y), the meridian section of a
!! body of revolution (`axi_element_t`: x = r, y = z, per radian, with the hoop strain).
!! Shapes: ELEM_Q1 (4-vertex quadrilateral) and ELEM_P1 (3-vertex triangle) of module config.
!! The kernels are module elements'; an element adds no arithmetic of its own, so a result
!! is the kernels' bit for bit. Adding an element: doc/developing.md, "Adding an element".
module element_types
  use kinds, only: wp
  use config, only: ELEM_Q1, ELEM_P1, elastic_law_t
  use elements, only: MAX_NVERT, MAX_NDOF, body_force_fn, ke_cache_t, element_nvert, element_stiffness, &
                      element_stress, element_stress_general, element_shape_integrals, element_body_force, &
                      axi_stiffness, axi_stress
  implicit none (type, external)
  private

  integer, parameter, public :: MODEL_PLANE_STRAIN = 1   !< plane strain: ezz = 0
  integer, parameter, public :: MODEL_PLANE_STRESS = 2   !< plane stress: szz = 0
  integer, parameter, public :: MODEL_AXISYMMETRIC = 3   !< meridian section of a body of revolution
  integer, parameter, public :: NSHAPE = 2               !< cell shapes known: ELEM_Q1, ELEM_P1

  !> An element: a cell shape under a kinematic model. Arrays follow module elements:
  !! xe(NDIM, MAX_NVERT) the vertex coordinates, element DOFs interleaved by vertex (vertex
  !! a, component c is local DOF NCOMP (a - 1) + c), ke(MAX_NDOF, MAX_NDOF).
  type, abstract, public :: element_t
    integer :: shape = 0        !< ELEM_Q1 or ELEM_P1 (module config)
    integer :: nvert = 0        !< vertices of the cell
    integer :: model = 0        !< MODEL_*
  contains
    procedure(stiffness_i), deferred :: stiffness
    procedure(stress_i), deferred :: stress
    procedure(integrals_i), deferred :: shape_integrals
    procedure(body_force_i), deferred :: body_force
  end type element_t

  abstract interface
    !> The cell's stiffness under law `law` (number `key` of its body, for the cache) and
    !! the smallest Jacobian determinant met (not positive: an inverted or degenerate cell).
    pure subroutine stiffness_i(self, xe, law, key, ke, minjac, cache)
      import :: element_t, elastic_law_t, ke_cache_t, wp, MAX_NVERT, MAX_NDOF
      class(element_t), intent(in) :: self
      real(wp), intent(in) :: xe(:, :)                 !< vertex coordinates [length]
      type(elastic_law_t), intent(in) :: law           !< the cell's material
      integer, intent(in) :: key                       !< the law's number in its body
      real(wp), intent(out) :: ke(:, :)                !< element stiffness [stress] (per radian: x [length])
      real(wp), intent(out) :: minjac                  !< smallest Jacobian determinant
      type(ke_cache_t), intent(inout) :: cache         !< the last stiffness computed (translated cells)
    end subroutine stiffness_i

    !> The cell's stress (at its centre) from its displacements ue (interleaved).
    pure subroutine stress_i(self, xe, ue, law, cs)
      import :: element_t, elastic_law_t, wp
      class(element_t), intent(in) :: self
      real(wp), intent(in) :: xe(:, :)                 !< vertex coordinates [length]
      real(wp), intent(in) :: ue(:)                    !< element displacements [length]
      type(elastic_law_t), intent(in) :: law           !< the cell's material
      real(wp), intent(out) :: cs(:)                   !< the stress components (NSTRESS) [stress]
    end subroutine stress_i

    !> w(a) = the integral of shape function a over the cell (per radian: weighted by r).
    pure subroutine integrals_i(self, xe, w)
      import :: element_t, wp
      class(element_t), intent(in) :: self
      real(wp), intent(in) :: xe(:, :)                 !< vertex coordinates [length]
      real(wp), intent(out) :: w(:)                    !< (MAX_NVERT) [length^NDIM] (per radian: x [length])
    end subroutine integrals_i

    !> Add the consistent nodal loads of a body force density bf to fe(NCOMP, MAX_NVERT).
    subroutine body_force_i(self, xe, bf, fe)
      import :: element_t, body_force_fn, wp
      class(element_t), intent(in) :: self
      real(wp), intent(in) :: xe(:, :)                 !< vertex coordinates [length]
      procedure(body_force_fn) :: bf                   !< body force density
      real(wp), intent(inout) :: fe(:, :)              !< nodal loads, added to [force]
    end subroutine body_force_i
  end interface

  !> A plane cell (plane strain or plane stress): the isotropic kernel for an isotropic law
  !! (its Lame parameters), the general B'DB kernel for any other.
  type, extends(element_t), public :: plane_element_t
  contains
    procedure :: stiffness => plane_stiffness
    procedure :: stress => plane_stress
    procedure :: shape_integrals => plane_integrals
    procedure :: body_force => plane_body_force
  end type plane_element_t

  !> A cell of the meridian section of a body of revolution (x = r >= 0, y = z): per radian,
  !! strains (err, ezz, grz, ett = ur/r), every integral weighted by r.
  type, extends(element_t), public :: axi_element_t
  contains
    procedure :: stiffness => axi_elem_stiffness
    procedure :: stress => axi_elem_stress
    procedure :: shape_integrals => axi_integrals
    procedure :: body_force => axi_elem_body_force
  end type axi_element_t

  !> One element of a table indexed by shape.
  type, public :: element_slot_t
    class(element_t), allocatable :: e
  end type element_slot_t

  public :: element_for, element_table, model_of

contains

  !> The model of a body: axisymmetric, or plane strain or plane stress.
  pure integer function model_of(axisymmetric, plane_strain)
    logical, intent(in) :: axisymmetric   !< the scene's bodies are sections of revolution
    logical, intent(in) :: plane_strain   !< .true. plane strain, .false. plane stress
    if (axisymmetric) then
      model_of = MODEL_AXISYMMETRIC
    else if (plane_strain) then
      model_of = MODEL_PLANE_STRAIN
    else
      model_of = MODEL_PLANE_STRESS
    end if
  end function model_of

  !> The element of a cell shape (ELEM_Q1, ELEM_P1) under a model (MODEL_*).
  function element_for(shape, model) result(e)
    integer, intent(in) :: shape          !< ELEM_Q1 or ELEM_P1
    integer, intent(in) :: model          !< MODEL_*
    class(element_t), allocatable :: e
    if (model == MODEL_AXISYMMETRIC) then
      allocate (axi_element_t :: e)
    else
      allocate (plane_element_t :: e)
    end if
    e%shape = shape
    e%nvert = element_nvert(shape)
    e%model = model
  end function element_for

  !> The elements of every shape under one model, indexed by shape: tab(cell_element(mesh, c)).
  subroutine element_table(model, tab)
    integer, intent(in) :: model                   !< MODEL_*
    type(element_slot_t), intent(out) :: tab(:)    !< (NSHAPE)
    integer :: s
    do s = 1, NSHAPE
      allocate (tab(s)%e, source=element_for(s, model))
    end do
  end subroutine element_table

  ! ---------------------------------------------------------------------------------
  ! Plane strain and plane stress
  ! ---------------------------------------------------------------------------------

  pure subroutine plane_stiffness(self, xe, law, key, ke, minjac, cache)
    class(plane_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    type(elastic_law_t), intent(in) :: law
    integer, intent(in) :: key
    real(wp), intent(out) :: ke(:, :), minjac
    type(ke_cache_t), intent(inout) :: cache
    if (law%isotropic) then
      call element_stiffness(self%shape, xe, law%lame_lambda, law%lame_mu, ke, minjac, cache, key=key)
    else
      call element_stiffness(self%shape, xe, 0.0_wp, 0.0_wp, ke, minjac, cache, dmat=law%d, key=key)
    end if
  end subroutine plane_stiffness

  pure subroutine plane_stress(self, xe, ue, law, cs)
    class(plane_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :), ue(:)
    type(elastic_law_t), intent(in) :: law
    real(wp), intent(out) :: cs(:)
    if (law%isotropic) then
      call element_stress(self%shape, xe, ue, law%lame_lambda, law%lame_mu, self%model == MODEL_PLANE_STRAIN, cs)
    else
      call element_stress_general(self%shape, xe, ue, law%d, cs)
    end if
  end subroutine plane_stress

  pure subroutine plane_integrals(self, xe, w)
    class(plane_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    real(wp), intent(out) :: w(:)
    call element_shape_integrals(self%shape, xe, w)
  end subroutine plane_integrals

  subroutine plane_body_force(self, xe, bf, fe)
    class(plane_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    procedure(body_force_fn) :: bf
    real(wp), intent(inout) :: fe(:, :)
    call element_body_force(self%shape, xe, bf, fe)
  end subroutine plane_body_force

  ! ---------------------------------------------------------------------------------
  ! Axisymmetric
  ! ---------------------------------------------------------------------------------

  pure subroutine axi_elem_stiffness(self, xe, law, key, ke, minjac, cache)
    class(axi_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    type(elastic_law_t), intent(in) :: law
    integer, intent(in) :: key
    real(wp), intent(out) :: ke(:, :), minjac
    type(ke_cache_t), intent(inout) :: cache   ! not used: a translate in r is not the same cell
    call axi_stiffness(self%shape, xe, law%d, ke, minjac)
  end subroutine axi_elem_stiffness

  pure subroutine axi_elem_stress(self, xe, ue, law, cs)
    class(axi_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :), ue(:)
    type(elastic_law_t), intent(in) :: law
    real(wp), intent(out) :: cs(:)
    call axi_stress(self%shape, xe, ue, law%d, cs)
  end subroutine axi_elem_stress

  pure subroutine axi_integrals(self, xe, w)
    class(axi_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    real(wp), intent(out) :: w(:)
    call element_shape_integrals(self%shape, xe, w, axisymmetric=.true.)
  end subroutine axi_integrals

  subroutine axi_elem_body_force(self, xe, bf, fe)
    class(axi_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    procedure(body_force_fn) :: bf
    real(wp), intent(inout) :: fe(:, :)
    call element_body_force(self%shape, xe, bf, fe, axisymmetric=.true.)
  end subroutine axi_elem_body_force

end module element_types
