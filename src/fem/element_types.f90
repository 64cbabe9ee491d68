!> The element as one type: what the assembly asks of a cell (its stiffness, its stress, the
!! integrals of its shape functions, the loads of a body force) behind one abstract type
!! `element_t`, one concrete type per kinematic model, and a factory that builds the element
!! of a cell shape and a model (`element_for`) or the table of every shape of a model
!! (`element_table`), as the Robin operators and the factorization back-ends are built.
!! The assembly never tests a shape or a model: it asks the element of the cell.
!!
!! Models: plane strain and plane stress (`plane_element_t`: x, y), the meridian section of a
!! body of revolution (`axi_element_t`: x = r, y = z, per radian, with the hoop strain).
!! solid bodies (`solid_element_t`: x, y, z; an isotropic law, its Lame parameters).
!! Shapes: ELEM_Q1 (4-vertex quadrilateral) and ELEM_P1 (3-vertex triangle) in the plane,
!! ELEM_HEX8 and ELEM_TET4 in space (module config). The kernels are module elements' and
!! elements_3d's; an element adds no arithmetic of its own, so a result is the kernels' bit
!! for bit. The arrays a caller passes have `element_sizes`'s extents. Adding an element: doc/developing.md, "Adding an element".
module element_types
  use kinds, only: wp
  use space, only: NDIM, NCOMP
  use config, only: ELEM_Q1, ELEM_P1, ELEM_HEX8, ELEM_TET4, NSHAPE, elastic_law_t, shape_vertices
  use elements, only: MAX_NVERT, MAX_NDOF, body_force_fn, ke_cache_t, element_nvert, element_stiffness, &
                      element_stress, element_stress_general, element_shape_integrals, element_body_force, &
                      axi_stiffness, axi_stress
  use elements_3d, only: HEX8_NVERT, TET4_NVERT, SOLID_MAX_NDOF, NVOIGT, isotropic_d3, solid_stiffness, solid_stress, &
                         solid_shape_integrals, hex8_gradients, tet4_gradients
  implicit none (type, external)
  private

  integer, parameter, public :: MODEL_PLANE_STRAIN = 1   !< plane strain: ezz = 0
  integer, parameter, public :: MODEL_PLANE_STRESS = 2   !< plane stress: szz = 0
  integer, parameter, public :: MODEL_AXISYMMETRIC = 3   !< meridian section of a body of revolution
  integer, parameter, public :: MODEL_SOLID = 4          !< a solid body (space: x, y, z)

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

  !> A cell of a solid body (x, y, z): Voigt stresses (sxx, syy, szz, syz, sxz, sxy), an
  !! isotropic law.
  type, extends(element_t), public :: solid_element_t
  contains
    procedure :: stiffness => solid_elem_stiffness
    procedure :: stress => solid_elem_stress
    procedure :: shape_integrals => solid_integrals
    procedure :: body_force => solid_body_force
  end type solid_element_t

  !> One element of a table indexed by shape.
  type, public :: element_slot_t
    class(element_t), allocatable :: e
  end type element_slot_t

  public :: element_for, element_table, model_of, element_sizes

contains

  !> The model of a body: solid (a 3D scene), axisymmetric, or plane strain or plane stress.
  integer function model_of(axisymmetric, plane_strain)
    logical, intent(in) :: axisymmetric   !< the scene's bodies are sections of revolution
    logical, intent(in) :: plane_strain   !< .true. plane strain, .false. plane stress
    if (NDIM == 3) then
      model_of = MODEL_SOLID
    else if (axisymmetric) then
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
    if (model == MODEL_SOLID) then
      allocate (solid_element_t :: e)
    else if (model == MODEL_AXISYMMETRIC) then
      allocate (axi_element_t :: e)
    else
      allocate (plane_element_t :: e)
    end if
    e%shape = shape
    e%nvert = shape_vertices(shape)
    e%model = model
  end function element_for

  !> The elements of every shape under one model, indexed by shape: tab(cell_element(mesh, c)).
  subroutine element_table(model, tab)
    integer, intent(in) :: model                   !< MODEL_*
    type(element_slot_t), intent(out) :: tab(:)    !< (NSHAPE)
    integer :: s
    do s = 1, NSHAPE
      if ((model == MODEL_SOLID) .neqv. (s == ELEM_HEX8 .or. s == ELEM_TET4)) cycle
      if (shape_vertices(s) == 0) cycle
      allocate (tab(s)%e, source=element_for(s, model))
    end do
  end subroutine element_table

  !> The extents of the arrays a caller passes an element of the run's dimension: vertex
  !! coordinates xe(NDIM, nv), stiffness ke(nd, nd), displacements ue(nd), nodal loads
  !! fe(NCOMP, nv), stresses cs(ns). In the plane the plane kernels' fixed MAX_NVERT and
  !! MAX_NDOF; in space those of the hexahedron.
  subroutine element_sizes(nv, nd, ns)
    integer, intent(out) :: nv, nd, ns
    if (NDIM == 3) then
      nv = HEX8_NVERT
      nd = SOLID_MAX_NDOF
      ns = NVOIGT
    else
      nv = MAX_NVERT
      nd = MAX_NDOF
      ns = 4
    end if
  end subroutine element_sizes

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

  ! ---------------------------------------------------------------------------------
  ! Solid
  ! ---------------------------------------------------------------------------------

  pure subroutine solid_elem_stiffness(self, xe, law, key, ke, minjac, cache)
    class(solid_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    type(elastic_law_t), intent(in) :: law
    integer, intent(in) :: key
    real(wp), intent(out) :: ke(:, :), minjac
    type(ke_cache_t), intent(inout) :: cache   ! not used
    real(wp) :: d(NVOIGT, NVOIGT)
    call isotropic_d3(law%lame_lambda, law%lame_mu, d)
    call solid_stiffness(self%nvert, xe, d, ke, minjac)
  end subroutine solid_elem_stiffness

  pure subroutine solid_elem_stress(self, xe, ue, law, cs)
    class(solid_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :), ue(:)
    type(elastic_law_t), intent(in) :: law
    real(wp), intent(out) :: cs(:)
    real(wp) :: d(NVOIGT, NVOIGT)
    call isotropic_d3(law%lame_lambda, law%lame_mu, d)
    call solid_stress(self%nvert, xe, ue, d, cs)
  end subroutine solid_elem_stress

  pure subroutine solid_integrals(self, xe, w)
    class(solid_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    real(wp), intent(out) :: w(:)
    call solid_shape_integrals(self%nvert, xe, w)
  end subroutine solid_integrals

  !> A body-force density by Gauss points: HEX8 2x2x2 (degree 3 per axis), TET4 the
  !! 4-point rule of degree 2.
  subroutine solid_body_force(self, xe, bf, fe)
    class(solid_element_t), intent(in) :: self
    real(wp), intent(in) :: xe(:, :)
    procedure(body_force_fn) :: bf
    real(wp), intent(inout) :: fe(:, :)
    real(wp), parameter :: gp = 0.577350269189625764509148780502_wp
    real(wp), parameter :: ta = 0.585410196624968500_wp, tb = 0.138196601125010500_wp
    real(wp) :: nfun(HEX8_NVERT), g(3, HEX8_NVERT), det, xq(3), bv(3), l(4)
    integer :: i, j, k, a, q
    if (self%nvert == HEX8_NVERT) then
      do k = -1, 1, 2
        do j = -1, 1, 2
          do i = -1, 1, 2
            call hex8_gradients(xe, i*gp, j*gp, k*gp, nfun, g, det)
            xq = matmul(xe(:, 1:HEX8_NVERT), nfun)
            call bf(xq, bv)
            do a = 1, HEX8_NVERT
              fe(:, a) = fe(:, a) + det*nfun(a)*bv
            end do
          end do
        end do
      end do
    else
      call tet4_gradients(xe(:, 1:TET4_NVERT), g(:, 1:TET4_NVERT), det)
      do q = 1, 4
        l = tb
        l(q) = ta
        xq = matmul(xe(:, 1:TET4_NVERT), l)
        call bf(xq, bv)
        do a = 1, TET4_NVERT
          fe(:, a) = fe(:, a) + (det/24.0_wp)*l(a)*bv     ! weight V/4 = det/24
        end do
      end do
    end if
  end subroutine solid_body_force

end module element_types
