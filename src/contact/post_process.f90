!> The fields a result shows, computed from the solution for the output to write: per
!! contact solution (the last result and each load step's) its normal rows as a view with the
!! tangential part of each node beside them (friction_view: force, shear, slip, the state
!! stick, slip or open) and each row's contact pressure; per body its nodal stresses, von
!! Mises, nodal contact pressure and the supports' reactions.
!!
!! The driver prepares a `result_fields_t` (prepare_fields, add_step) over the run's data, which
!! it points to, not copies; the writer asks it for one solution's contact fields
!! (step_contact) or one body's fields (body_fields) when it writes them, so that a body's
!! fields live only while they are written (bodies may be asked for on several threads at once).
module post_process
  use kinds, only: wp
  use space, only: NDIM, NCOMP, NSTRESS, dof_node
  use config, only: deck_t
  use mesh, only: mesh_t
  use body_system, only: body_system_t
  use assembly, only: nodal_stress, support_reactions
  use contact_interface, only: interface_t
  use contact_types, only: contact_result_t
  use friction_view, only: tangential_t, split_friction
  implicit none (type, external)
  private

  !> One body's fields, in the mesh's node order.
  type, public :: body_fields_t
    real(wp), allocatable :: stress(:, :)     !< (NSTRESS, nnode) nodal stresses, nodal_stress's order [stress]
    real(wp), allocatable :: von_mises(:)     !< (nnode) von Mises stress [stress]
    real(wp), allocatable :: pressure(:)      !< (nnode) contact pressure, 0 off the contact lines [stress]
    real(wp), allocatable :: reaction(:, :)   !< (NCOMP, nnode) the supports' forces, 0 off the supports [force]
  end type body_fields_t

  !> One contact solution as the output shows it: one entry per contact node.
  type, public :: contact_fields_t
    type(contact_result_t) :: res             !< the solution on the normal rows (split_friction)
    type(tangential_t) :: tg                  !< the tangential part of each node (friction)
    real(wp), allocatable :: pressure(:)      !< (m) normal force / tributary length of each row [stress]
    integer, allocatable :: active(:)         !< (m) 1 where the row carries a normal force, else 0
    !> (m) in space with friction: the length of each node's shear (tg%shear) [stress]
    real(wp), allocatable :: shear_magnitude(:)
    real(wp) :: normal_force_sum = 0.0_wp     !< the sum of the rows' normal forces [force]
  end type contact_fields_t

  !> A load step's solution, as the driver keeps it.
  type :: step_source_t
    integer :: stage = 1                                  !< the stage it ramps
    real(wp) :: load_factor = 1.0_wp                      !< of its stage's loads [-]
    type(contact_result_t), pointer :: res => null()      !< its contact solution (all rows)
    real(wp), pointer, contiguous :: u(:, :) => null()    !< (maxndof, bodies) its displacements [length]
  end type step_source_t

  !> The fields of a result: the view of the contact rows and the last solution's contact
  !! fields computed once (prepare_fields), the rest on request from the run's data.
  type, public :: result_fields_t
    type(interface_t) :: itf                  !< the normal rows of the contact line (split_friction)
    type(contact_fields_t) :: last            !< the last result's contact fields
    type(deck_t), pointer :: d => null()
    type(mesh_t), pointer :: msh(:) => null()
    type(body_system_t), pointer :: sys(:) => null()
    type(interface_t), pointer :: itf_all => null()       !< contact rows of all pairs (normal and tangential)
    real(wp), pointer, contiguous :: u(:, :) => null()    !< (maxndof, bodies) the last displacements
    real(wp), pointer, contiguous :: rf(:, :) => null()   !< (maxndof, bodies) their supports' forces
    type(step_source_t), allocatable :: step(:)           !< the load steps (add_step)
  contains
    procedure :: step_contact
    procedure :: body_fields
  end type result_fields_t

  public :: prepare_fields, add_step

contains

  !> The fields of the result of a run: its data (pointed to; they must outlive f's use), the
  !! view of its contact rows and the last solution's contact fields; no load step yet.
  subroutine prepare_fields(f, d, msh, sys, itf_all, res_all, u, rf)
    type(result_fields_t), intent(out) :: f
    type(deck_t), intent(in), target :: d                     !< the effective deck
    type(mesh_t), intent(in), target :: msh(:)                !< meshes
    type(body_system_t), intent(in), target :: sys(:)         !< systems (DOF maps, loads)
    type(interface_t), intent(in), target :: itf_all          !< contact rows of all pairs
    type(contact_result_t), intent(in) :: res_all             !< the last contact solution
    real(wp), intent(in), target, contiguous :: u(:, :)       !< (maxndof, bodies) full displacements
    real(wp), intent(in), target, contiguous :: rf(:, :)      !< (maxndof, bodies) the supports' forces (support_reactions)
    f%d => d
    f%msh => msh
    f%sys => sys
    f%itf_all => itf_all
    f%u => u
    f%rf => rf
    allocate (f%step(0))
    call split_friction(itf_all, res_all, f%itf, f%last%res, f%last%tg)
    call row_fields(f%itf, f%last)
  end subroutine prepare_fields

  !> Append a load step (its stage, load factor, contact solution and displacements, pointed
  !! to) to the fields of f.
  subroutine add_step(f, stage, load_factor, res, u)
    type(result_fields_t), intent(inout) :: f
    integer, intent(in) :: stage                              !< the stage it ramps
    real(wp), intent(in) :: load_factor                       !< of its stage's loads [-]
    type(contact_result_t), intent(in), target :: res         !< its contact solution (all rows)
    real(wp), intent(in), target, contiguous :: u(:, :)       !< (maxndof, bodies) its displacements
    type(step_source_t), allocatable :: grown(:)
    integer :: n
    n = size(f%step)
    allocate (grown(n + 1))
    grown(1:n) = f%step
    grown(n + 1)%stage = stage
    grown(n + 1)%load_factor = load_factor
    grown(n + 1)%res => res
    grown(n + 1)%u => u
    call move_alloc(grown, f%step)
  end subroutine add_step

  !> The contact fields of load step k (the last result's are f%last); a step not solved (no
  !! normal forces) has no pressure.
  subroutine step_contact(f, k, cf)
    class(result_fields_t), intent(in) :: f
    integer, intent(in) :: k                                  !< the step (add_step's order)
    type(contact_fields_t), intent(out) :: cf
    type(interface_t) :: itf
    call split_friction(f%itf_all, f%step(k)%res, itf, cf%res, cf%tg)
    if (.not. allocated(cf%res%lam)) return
    call row_fields(itf, cf)
  end subroutine step_contact

  !> Body a's fields in load step k (k = 0: the last result): its nodal stresses and von Mises
  !! (assembly's nodal_stress), its nodal contact pressure from the rows' pressures `pres`
  !! of that solution (nodal_pressure) and the supports' forces on it (the last result's
  !! those of f%rf; a step's from its displacements and its applied loads: the earlier stages
  !! whole, its own times its load factor). Bodies may be asked for on several threads at once.
  subroutine body_fields(f, k, a, pres, bf)
    class(result_fields_t), intent(in) :: f
    integer, intent(in) :: k                                  !< the step (0: the last result)
    integer, intent(in) :: a                                  !< the body
    real(wp), intent(in) :: pres(:)                           !< (m) pressure of each row of that solution [stress]
    type(body_fields_t), intent(out) :: bf
    real(wp), allocatable :: fa(:), rf(:)
    integer :: nn, s
    associate (msh => f%msh(a), sy => f%sys(a))
      nn = msh%nnode
      allocate (bf%stress(NSTRESS, nn), bf%von_mises(nn), bf%pressure(nn))
      if (k == 0) then
        call nodal_stress(msh, f%d%body(a), f%d%plane_strain, f%u(1:sy%ndof, a), bf%stress, bf%von_mises)
      else
        call nodal_stress(msh, f%d%body(a), f%d%plane_strain, f%step(k)%u(1:NCOMP*nn, a), bf%stress, bf%von_mises)
      end if
      call nodal_pressure(f%itf, a, pres, bf%pressure)
      if (k == 0) then
        bf%reaction = reshape(f%rf(1:sy%ndof, a), [NCOMP, nn])
        return
      end if
      allocate (fa(sy%ndof), rf(sy%ndof))
      if (allocated(sy%fa_stage)) then
        fa = 0.0_wp
        do s = 1, f%step(k)%stage - 1
          fa = fa + sy%fa_stage(:, s)
        end do
        fa = fa + f%step(k)%load_factor*sy%fa_stage(:, f%step(k)%stage)
      else
        fa = f%step(k)%load_factor*sy%f_applied
      end if
      call support_reactions(msh, f%d%body(a), f%d%plane_strain, sy, f%step(k)%u(1:sy%ndof, a), fa, rf)
      bf%reaction = reshape(rf, [NCOMP, nn])
    end associate
  end subroutine body_fields

  !> The fields of each row of cf's solution (cf%res, cf%tg): its contact pressure, its normal
  !! force over its tributary length (0 where that is 0); whether it is active; in space
  !! with friction its shear's length; and the sum of the normal forces.
  subroutine row_fields(itf, cf)
    type(interface_t), intent(in) :: itf              !< the normal rows
    type(contact_fields_t), intent(inout) :: cf
    allocate (cf%pressure(itf%m))
    where (itf%trib > 0.0_wp)
      cf%pressure = cf%res%lam/itf%trib
    elsewhere
      cf%pressure = 0.0_wp
    end where
    cf%active = merge(1, 0, cf%res%lam > 0.0_wp)
    if (cf%tg%on .and. NDIM == 3) cf%shear_magnitude = norm2(cf%tg%shear, dim=1)
    cf%normal_force_sum = sum(cf%res%lam)
  end subroutine row_fields

  !> The contact pressure as a nodal field of body a (0 off its contact lines): where it is
  !! a pair's slave the rows' pressures; on the master the mean of the pressures of the rows that reach a
  !! node, weighted by their mortar weight times tributary length (a uniform pressure stays
  !! uniform, and matching lines give the slave's values).
  subroutine nodal_pressure(itf, a, pres, p)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a                  !< body
    real(wp), intent(in) :: pres(:)           !< (m) pressure of each row [stress]
    real(wp), intent(out) :: p(:)             !< (nnode) nodal field [stress]
    real(wp), allocatable :: den(:), ps(:)
    logical, allocatable :: on_slave(:)
    integer :: k, e, i, q, sd
    real(wp) :: w
    allocate (den(size(p)), ps(size(p)), on_slave(size(p)))
    p = 0.0_wp
    den = 0.0_wp
    on_slave = .false.
    do q = 1, itf%npair
      do sd = 1, 2
        if (itf%pair_body(sd, q) /= a) cycle
        if (sd == itf%pair_slave(q)) then
          do k = itf%pair_ptr(q), itf%pair_ptr(q + 1) - 1
            ps(itf%node(k, sd)) = pres(k)
            on_slave(itf%node(k, sd)) = .true.
          end do
          cycle
        end if
        do k = itf%pair_ptr(q), itf%pair_ptr(q + 1) - 1
          ! a node's entries (x, y, z) are adjacent: weight |w n| = w
          do e = itf%b(sd)%ptr(k), itf%b(sd)%ptr(k + 1) - NCOMP, NCOMP
            i = dof_node(itf%b(sd)%dof(e))
            if (NCOMP == 2) then
              w = hypot(itf%b(sd)%val(e), itf%b(sd)%val(e + 1))
            else
              w = norm2(itf%b(sd)%val(e:e + NCOMP - 1))
            end if
            if (w <= 1.0e-12_wp) cycle             ! a rounding-level weight of a matching line
            w = w*itf%trib(k)
            p(i) = p(i) + w*pres(k)
            den(i) = den(i) + w
          end do
        end do
      end do
    end do
    where (den > 0.0_wp) p = p/den
    where (on_slave) p = ps
  end subroutine nodal_pressure

end module post_process
