!> Plane linear elasticity on one body's mesh (module mesh: a structured grid or a mesh
!! read from a file): the stiffness on its free DOFs in compressed sparse columns, the
!! consistent load of its tractions and body force, elimination of prescribed displacements,
!! reactions and nodal stresses. The per-element work (shape functions, element stiffness,
!! loads, stress) is module elements'; the supports and the free-DOF numbering module
!! supports', the sparsity pattern module stiffness_pattern's, the rigid motions of a body
!! held only by contact module rigid_modes'. This module loops over cells and sides and
!! places the results.
!!
!! DOFs: node k, component c (1 = x, 2 = y) is global dof 2*(k-1)+c. Free DOFs are
!! numbered in increasing global order, so the stiffness on free DOFs keeps the structure
!! of the node numbering (a band on a grid). Isotropic material, plane strain or plane
!! stress; Q1 with 2x2 Gauss, P1 with one point (exact). Units are whatever the deck uses,
!! consistently: [length], [stress] = [force]/[length]^2, forces per unit thickness.
module assembly
  use kinds, only: wp
  use space, only: NDIM, NCOMP, node_dof
  use, intrinsic :: iso_fortran_env, only: int16
  use strings, only: i2s, sci
  use sorting, only: sort_by_key
  use config, only: body_cfg_t, elastic_law_t, body_stiffness, traction_cfg_t, boundary_cfg_t, ELEM_Q1, ELEM_P1, ELEM_MIXED, ELEM_HEX8, ELEM_TET4, NSHAPE, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_TOP, side_names, BC_FREE, BC_DISPLACEMENT
  use mesh, only: mesh_t, side_nodes, group_index, nodes_only, nodes_only_refusal, cell_element, cell_vertices
  use elements, only: body_force_fn, ke_cache_t, ke_cache_init, edge_traction
  use element_types, only: element_slot_t, element_table, model_of, element_sizes
  use elements_3d, only: face_traction, face_area_normal
  use material_laws, only: isotropic_law
  use linop, only: csc_symv
  use body_system, only: body_system_t
  use supports, only: prescribed_dofs, group_conditions, unknown_group, number_free_dofs
  use stiffness_pattern, only: build_pattern
  use rigid_modes, only: rigid_kernel, choose_fixing, rigid_motion_name
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  implicit none (type, external)
  private

  public :: assemble_body, expand, residual_full, support_reactions, nodal_stress, csc_matvec, lame_parameters, cell_triplets
  public :: body_system_t, body_force_fn, rigid_motion_name

contains

  !> The elastic laws of a body: its resolved laws (body%law, from the deck), or for a body
  !! built in code without them the isotropic law of its young and poisson.
  function body_laws(body, plane_strain) result(laws)
    type(body_cfg_t), intent(in) :: body
    logical, intent(in) :: plane_strain
    type(elastic_law_t), allocatable :: laws(:)
    if (allocated(body%law)) then
      laws = body%law
    else
      allocate (laws(1))
      call isotropic_law(body%young, body%poisson, plane_strain, laws(1))
      laws(1)%density = body%density
    end if
  end function body_laws

  !> The law of cell c: mesh%cell_law's, or 1.
  pure integer function law_of(mesh, c)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: c
    law_of = 1
    if (allocated(mesh%cell_law)) law_of = mesh%cell_law(c)
  end function law_of

  !> Lame parameters of the body: plane strain uses lambda, mu; plane stress the
  !! reduced lambda* = 2 lambda mu / (lambda + 2 mu).
  pure subroutine lame_parameters(body, plane_strain, lame_lambda, lame_mu)
    type(body_cfg_t), intent(in) :: body     !< young [stress], poisson [-]
    logical, intent(in) :: plane_strain      !< .true. plane strain, .false. plane stress
    real(wp), intent(out) :: lame_lambda     !< (effective) first Lame parameter [stress]
    real(wp), intent(out) :: lame_mu         !< shear modulus [stress]
    real(wp) :: e, nu
    e = body%young
    nu = body%poisson
    lame_mu = e/(2.0_wp*(1.0_wp + nu))
    if (plane_strain) then
      lame_lambda = e*nu/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
    else
      lame_lambda = e*nu/(1.0_wp - nu*nu)   ! = 2 lambda mu / (lambda + 2 mu)
    end if
  end subroutine lame_parameters

  !> Assemble the stiffness of one body on its free DOFs (CSC, full symmetric pattern) and
  !! its consistent load. Side conditions come from body%bc: clamped (both components 0),
  !! roller (normal component 0), displacement (both components = body%u_side(:,side)),
  !! free and contact (nothing). Prescribed DOFs are eliminated with the lifting
  !! f -= K_fd u_d. Tractions with %body == body%id are integrated exactly on the side.
  !! On an impossible input `err` says why (ERR_INPUT; ERR_NUMERICAL for a LAPACK or
  !! internal failure), naming the body, and `sys` is incomplete.
  subroutine assemble_body(mesh, body, plane_strain, tractions, ntraction, sys, err, &
                           u_prescribed, body_force, boundaries, matrix, contact_groups, nstage, body_load)
    type(mesh_t), intent(in) :: mesh                     !< the body's mesh (mesh_build)
    type(body_cfg_t), intent(in) :: body                 !< material, side conditions
    logical, intent(in) :: plane_strain                  !< .true. plane strain, .false. plane stress
    type(traction_cfg_t), intent(in) :: tractions(:)     !< tractions of the deck (any body)
    integer, intent(in) :: ntraction                     !< how many of `tractions` are in use
    type(body_system_t), intent(out) :: sys              !< the assembled system
    type(error_t), intent(out) :: err                    !< the failure, if any
    !> (ndof) optional per-dof prescribed values [length]: where given, they replace the
    !! side values at every DOF that the side conditions prescribe (which DOFs are
    !! prescribed is still decided by body%bc).
    real(wp), intent(in), optional :: u_prescribed(:)
    !> optional body force density, integrated with 3x3 Gauss (Q1) or a degree-2 rule (P1)
    procedure(body_force_fn), optional :: body_force
    !> optional prescribed components on named edge groups (&boundary; those of other
    !! bodies are skipped), applied after the side conditions, in order
    type(boundary_cfg_t), intent(in), optional :: boundaries(:)
    !> .false.: no stiffness matrix (colptr, rowind, val stay unallocated, k_norm 0): the
    !! DOF numbering and the load only, for a run whose ranks each assemble their share of
    !! the cells (cell_triplets); default .true.
    logical, intent(in), optional :: matrix
    !> the body's contact groups (one per pair it is in), kept clear of fixing DOFs when the
    !! body is held only by contact (a rectangle's 'contact' side is too)
    character(len=*), intent(in), optional :: contact_groups(:)
    !> the deck's load stages: each stage's load vectors too (sys%f_stage, u_stage,
    !! fa_stage), for load steps; absent: none
    integer, intent(in), optional :: nstage
    !> (2, nstage or 1, laws) a constant body force per volume of each stage in the cells of
    !! each elastic law [force/length^3] (&body_force: density x gravity + force, the law's
    !! density); the whole load takes their sum over the stages
    real(wp), intent(in), optional :: body_load(:, :, :)
    logical, allocatable :: prescribed(:)
    integer(int16), allocatable :: cell_row(:, :, :)
    type(elastic_law_t), allocatable :: laws(:)
    type(element_slot_t) :: elems(NSHAPE)
    logical :: with_k

    with_k = .true.
    if (present(matrix)) with_k = matrix

    sys%id = body%id
    call check_input(mesh, body, tractions, ntraction, err, u_prescribed)
    if (err%failed()) return
    laws = body_laws(body, plane_strain)
    if (allocated(mesh%cell_law)) then
      if (maxval(mesh%cell_law) > size(laws)) then
        call err%set(ERR_NUMERICAL, 'body '//i2s(body%id)//': internal error, a cell''s law is '// &
                     'beyond the body''s laws')
        return
      end if
    end if
    if (present(body_load)) then
      if (size(body_load, 3) /= size(laws)) then
        call err%set(ERR_NUMERICAL, 'body '//i2s(body%id)//': internal error, body forces for '// &
                     'another number of laws')
        return
      end if
    end if

    call prescribed_dofs(mesh, body, prescribed, sys, u_prescribed)
    if (present(boundaries)) then
      call group_conditions(mesh, body%id, boundaries, prescribed, sys, err)
      if (err%failed()) return
    end if
    if (mesh%axisymmetric) then
      call axis_conditions(mesh, prescribed, sys, err)
      if (err%failed()) return
    end if
    ! rigid motions the supports leave free: a body held only by contact
    call rigid_kernel(mesh, prescribed, sys, err, mesh%axisymmetric)
    if (err%failed()) return
    if (sys%nrig > 0) then
      call choose_fixing(mesh, body, prescribed, sys, err, contact_groups)
      if (err%failed()) return
    end if
    call number_free_dofs(prescribed, sys)
    if (with_k) then
      call build_pattern(mesh, sys, err, cell_row)
      if (err%failed()) return
    end if
    if (present(body_load)) then
      call applied_loads(mesh, body%id, tractions(1:ntraction), sys, err, body_force, sum(body_load, dim=2))
    else
      call applied_loads(mesh, body%id, tractions(1:ntraction), sys, err, body_force)
    end if
    if (err%failed()) return
    call element_table(model_of(mesh%axisymmetric, plane_strain), elems)
    call stiffness_and_lifting(mesh, laws, elems, sys, err, with_k, cell_row)
    if (err%failed()) return
    if (allocated(cell_row)) deallocate (cell_row)
    call add_applied_loads(sys)
    if (present(nstage)) then
      call stage_loads(mesh, laws, tractions(1:ntraction), nstage, sys, err, body_force, body_load)
      if (err%failed()) return
    end if
    if (with_k) sys%k_norm = stiffness_norm(sys)
    if (sys%nrig > 0) call check_kernel(mesh, body, plane_strain, sys, err)
  end subroutine assemble_body

  !> The stiffness entries of cells c1..c2 on the free DOFs as coordinate triplets of the
  !! lower triangle (1-based free indices, row >= column; a DOF pair shared by cells
  !! appears once per cell, to be summed): one rank's share of the matrix, MUMPS's
  !! distributed assembled input (ICNTL(18) = 3). sys needs its DOF numbering only
  !! (assemble_body with matrix=.false.). err = ERR_INPUT on a cell with a non-positive Jacobian.
  subroutine cell_triplets(mesh, body, plane_strain, sys, c1, c2, irn, jcn, a, err)
    type(mesh_t), intent(in) :: mesh                     !< the body's mesh
    type(body_cfg_t), intent(in) :: body                 !< material
    logical, intent(in) :: plane_strain                  !< .true. plane strain, .false. plane stress
    type(body_system_t), intent(in) :: sys               !< the body's DOF numbering (free_of)
    integer, intent(in) :: c1, c2                        !< the cells, c1..c2 (none if c2 < c1)
    integer, allocatable, intent(out) :: irn(:), jcn(:)  !< row and column of each entry (free, 1-based)
    real(wp), allocatable, intent(out) :: a(:)           !< the entries [stress]
    type(error_t), intent(out) :: err                    !< the bad cell, if any
    integer :: c, nd, i, j, q, fi, fj, nvx, ndx, nsx
    integer, allocatable :: ldof(:)
    real(wp), allocatable :: ke(:, :)
    type(ke_cache_t) :: cache
    integer, allocatable :: ti(:), tj(:)
    real(wp), allocatable :: ta(:)
    type(elastic_law_t), allocatable :: laws(:)
    type(element_slot_t) :: elems(NSHAPE)

    laws = body_laws(body, plane_strain)
    call element_table(model_of(mesh%axisymmetric, plane_strain), elems)
    call element_sizes(nvx, ndx, nsx)
    allocate (ldof(ndx), ke(ndx, ndx))
    call ke_cache_init(cache, maxval(abs(mesh%xy)))
    q = max(0, c2 - c1 + 1)*(ndx*(ndx + 1))/2
    allocate (ti(q), tj(q), ta(q))
    q = 0
    do c = max(1, c1), min(mesh%ncell, c2)
      call cell_stiffness(mesh, sys%id, c, laws, elems, cache, ke, nd, ldof, err)
      if (err%failed()) return
      do j = 1, nd
        fj = sys%free_of(ldof(j))
        if (fj == 0) cycle
        do i = 1, nd
          fi = sys%free_of(ldof(i))
          if (fi < fj) cycle
          q = q + 1
          ti(q) = fi
          tj(q) = fj
          ta(q) = ke(i, j)
        end do
      end do
    end do
    irn = ti(1:q)
    jcn = tj(1:q)
    a = ta(1:q)
  end subroutine cell_triplets

  !> Check the arguments of assemble_body: a built mesh of a known element, a valid
  !! material, known side conditions, tractions on sides 1..4, u_prescribed of size ndof.
  subroutine check_input(mesh, body, tractions, ntraction, err, u_prescribed)
    type(mesh_t), intent(in) :: mesh
    type(body_cfg_t), intent(in) :: body
    type(traction_cfg_t), intent(in) :: tractions(:)
    integer, intent(in) :: ntraction
    type(error_t), intent(out) :: err
    real(wp), intent(in), optional :: u_prescribed(:)
    integer :: side, t
    character(len=512) :: emsg

    if (mesh%nnode < 1 .or. .not. allocated(mesh%xy) .or. .not. allocated(mesh%cells)) then
      write (emsg, '(a,i0,a)') 'body ', body%id, ': the mesh is empty (call mesh_build first)'
      call err%set(ERR_INPUT, emsg)
      return
    end if
    if (.not. (NDIM == 2 .and. (mesh%element == ELEM_Q1 .or. mesh%element == ELEM_P1 .or. mesh%element == ELEM_MIXED)) &
        .and. .not. (NDIM == 3 .and. (mesh%element == ELEM_HEX8 .or. mesh%element == ELEM_TET4 .or. &
                                      mesh%element == ELEM_MIXED))) then
      write (emsg, '(a,i0,a,i0)') 'body ', body%id, ': unknown element code ', mesh%element
      call err%set(ERR_INPUT, emsg)
      return
    end if
    if (.not. (body%young > 0.0_wp)) then
      write (emsg, '(a,i0,a,es12.4)') 'body ', body%id, ': Young''s modulus must be positive, got ', body%young
      call err%set(ERR_INPUT, emsg)
      return
    end if
    if (.not. (body%poisson > -1.0_wp .and. body%poisson < 0.5_wp)) then
      write (emsg, '(a,i0,a,es12.4)') 'body ', body%id, ': Poisson''s ratio must lie in (-1, 0.5), got ', &
        body%poisson
      call err%set(ERR_INPUT, emsg)
      return
    end if
    do side = 1, 2*NDIM
      if (body%bc(side) < BC_FREE .or. body%bc(side) > BC_DISPLACEMENT) then
        write (emsg, '(a,i0,a,a,a,i0)') 'body ', body%id, ': unknown condition code on side ', &
          trim(side_names(side)), ': ', body%bc(side)
        call err%set(ERR_INPUT, emsg)
        return
      end if
    end do
    if (ntraction < 0 .or. ntraction > size(tractions)) then
      write (emsg, '(a,i0,a,i0,a)') 'ntraction = ', ntraction, ' but only ', size(tractions), &
        ' tractions were passed'
      call err%set(ERR_INPUT, emsg)
      return
    end if
    do t = 1, ntraction
      if (tractions(t)%body /= body%id) cycle
      if (len_trim(tractions(t)%group) > 0) cycle
      if (.not. (mesh%structured .or. mesh%box)) then
        write (emsg, '(a,i0,a,i0,a)') 'traction ', t, ' on body ', body%id, &
          ' is on a side, but the body comes from a mesh file: load a group'
        call err%set(ERR_INPUT, emsg)
        return
      end if
      if (tractions(t)%side < SIDE_LEFT .or. tractions(t)%side > 2*NDIM) then
        write (emsg, '(a,i0,a,i0,a,i0,a,i0)') 'traction ', t, ' on body ', body%id, &
          ' has side index ', tractions(t)%side, ', outside 1..', 2*NDIM
        call err%set(ERR_INPUT, emsg)
        return
      end if
    end do
    if (present(u_prescribed)) then
      if (size(u_prescribed) /= NCOMP*mesh%nnode) then
        write (emsg, '(a,i0,a,i0,a,i0)') 'body ', body%id, ': u_prescribed has ', size(u_prescribed), &
          ' values, expected ndof = ', NCOMP*mesh%nnode
        call err%set(ERR_INPUT, emsg)
        return
      end if
    end if
  end subroutine check_input

  !> A meridian section's nodes on the axis (x within 1e-9 of the section's extent of 0)
  !! have ur = 0: prescribed, a support of no load. err = ERR_INPUT where a support already
  !! prescribes a nonzero ur there (a node on the axis cannot move off it).
  subroutine axis_conditions(mesh, prescribed, sys, err)
    type(mesh_t), intent(in) :: mesh
    logical, intent(inout) :: prescribed(:)
    type(body_system_t), intent(inout) :: sys
    type(error_t), intent(out) :: err
    real(wp) :: tol
    integer :: k
    tol = 1.0e-9_wp*max(maxval(mesh%xy(1, :)) - minval(mesh%xy(1, :)), maxval(mesh%xy(2, :)) - minval(mesh%xy(2, :)))
    do k = 1, mesh%nnode
      if (abs(mesh%xy(1, k)) > tol) cycle
      if (prescribed(node_dof(k, 1)) .and. sys%u_fixed(node_dof(k, 1)) /= 0.0_wp) then
        call err%set(ERR_INPUT, 'body '//i2s(sys%id)//': node '//i2s(mesh%node_tag(k))// &
                     ' lies on the axis (x = 0), where ur = 0, but a support prescribes ux = '// &
                     sci(sys%u_fixed(node_dof(k, 1)))//' there; a body of revolution''s axis cannot move off it')
        return
      end if
      prescribed(node_dof(k, 1)) = .true.
      sys%u_fixed(node_dof(k, 1)) = 0.0_wp
      sys%dof_stage(node_dof(k, 1)) = 0
    end do
  end subroutine axis_conditions

  !> The kernel is computed, not guessed: |K R| over the DOFs that are not prescribed
  !! (fixing DOFs included) must be at rounding level, 1e-9 |K| |R|. err = ERR_INPUT otherwise.
  subroutine check_kernel(mesh, body, plane_strain, sys, err)
    type(mesh_t), intent(in) :: mesh
    type(body_cfg_t), intent(in) :: body
    logical, intent(in) :: plane_strain
    type(body_system_t), intent(inout) :: sys
    type(error_t), intent(out) :: err
    character(len=512) :: emsg
    real(wp), allocatable :: kr(:), zero(:)
    real(wp) :: worst, knorm, lo
    integer :: j
    logical, allocatable :: live(:)
    allocate (kr(sys%ndof), zero(sys%ndof), live(sys%ndof))
    zero = 0.0_wp
    live = sys%free_of > 0
    live(sys%fixing) = .true.
    ! no assembled matrix (MUMPS ranks): Young's modulus is the scale of K's entries
    knorm = sys%k_norm
    if (knorm <= 0.0_wp) then
      call body_stiffness(body, lo, knorm)
      knorm = max(knorm, tiny(1.0_wp))
    end if
    worst = 0.0_wp
    do j = 1, sys%nrig
      call residual_full(mesh, body, plane_strain, sys%rig(:, j), zero, kr)
      worst = max(worst, maxval(abs(kr), mask=live)/(knorm*max(maxval(abs(sys%rig(:, j))), tiny(1.0_wp))))
    end do
    sys%rig_residual = worst
    if (worst > 1.0e-9_wp) then
      write (emsg, '(a,i0,a,es10.3,a)') 'body ', body%id, ': its rigid-motion kernel fails the check |K R| = ', &
        worst, ' |K| |R| (expected rounding level)'
      call err%set(ERR_INPUT, emsg)
    end if
  end subroutine check_kernel

  !> The applied nodal loads on all DOFs (sys%f_applied): the tractions on this body,
  !! then the body forces if any (a density function, a constant); sys%f = 0. err =
  !! ERR_INPUT when a traction names a group the body does not have.
  subroutine applied_loads(mesh, body_id, tractions, sys, err, body_force, body_load)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: body_id
    type(traction_cfg_t), intent(in) :: tractions(:)
    type(body_system_t), intent(inout) :: sys
    type(error_t), intent(out) :: err
    procedure(body_force_fn), optional :: body_force
    !> (2, laws) constant body force per volume in the cells of each law [force/length^3]
    real(wp), intent(in), optional :: body_load(:, :)
    integer :: t, g
    character(len=:), allocatable :: why

    allocate (sys%f(sys%n), sys%f_applied(sys%ndof))
    sys%f = 0.0_wp
    sys%f_applied = 0.0_wp
    do t = 1, size(tractions)
      if (tractions(t)%body /= body_id) cycle
      if (len_trim(tractions(t)%group) > 0) then
        g = group_index(mesh, tractions(t)%group)
        if (g == 0) then
          call unknown_group(mesh, tractions(t)%group, why)
          call err%set(ERR_INPUT, 'body '//i2s(body_id)//': '//trim(tractions(t)%origin)//': '//why)
          return
        end if
        if (nodes_only(mesh, g)) then
          call nodes_only_refusal(mesh, g, 'a traction needs', why)
          call err%set(ERR_INPUT, 'body '//i2s(body_id)//': '//trim(tractions(t)%origin)//': '//why)
          return
        end if
        if (NDIM == 3) then
          call add_face_traction(mesh, g, tractions(t), sys%f_applied)
        else
          call add_group_traction(mesh, g, tractions(t), sys%f_applied)
        end if
      else if (NDIM == 3) then     ! a box's side is its group
        call add_face_traction(mesh, tractions(t)%side, tractions(t), sys%f_applied)
      else
        call add_traction(mesh, tractions(t), sys%f_applied)
      end if
    end do
    if (present(body_force)) call add_body_force(mesh, body_force, sys%f_applied)
    if (present(body_load)) then
      if (any(body_load /= 0.0_wp)) call add_constant_body_force(mesh, body_load, sys%f_applied)
    end if
  end subroutine applied_loads

  !> Each stage's load vectors (sys%f_stage, u_stage, fa_stage): its tractions, its
  !! prescribed values (sys%dof_stage) and their lifting, as the whole load is assembled;
  !! the body force function is stage 1's, the constant body force column s stage s's. One
  !! stage: the whole load's vectors.
  subroutine stage_loads(mesh, laws, tractions, nstage, sys, err, body_force, body_load)
    type(mesh_t), intent(in) :: mesh
    type(elastic_law_t), intent(in) :: laws(:)
    type(traction_cfg_t), intent(in) :: tractions(:)
    integer, intent(in) :: nstage
    type(body_system_t), intent(inout) :: sys
    type(error_t), intent(out) :: err
    procedure(body_force_fn), optional :: body_force
    real(wp), intent(in), optional :: body_load(:, :, :)
    real(wp), allocatable :: f_all(:), u_all(:), fa_all(:)
    real(wp) :: bl(NCOMP, size(laws))
    type(element_slot_t) :: elems(NSHAPE)
    integer :: s
    sys%nstage = nstage
    allocate (sys%f_stage(sys%n, nstage), sys%u_stage(sys%ndof, nstage), sys%fa_stage(sys%ndof, nstage))
    if (nstage == 1) then
      sys%f_stage(:, 1) = sys%f
      sys%u_stage(:, 1) = sys%u_fixed
      sys%fa_stage(:, 1) = sys%f_applied
      return
    end if
    call move_alloc(sys%f, f_all)
    call move_alloc(sys%u_fixed, u_all)
    call move_alloc(sys%f_applied, fa_all)
    do s = 1, nstage
      sys%u_fixed = merge(u_all, 0.0_wp, sys%dof_stage == s)
      bl = 0.0_wp
      if (present(body_load)) then
        if (s <= size(body_load, 2)) bl = body_load(:, s, :)
      end if
      if (s == 1) then
        call applied_loads(mesh, sys%id, pack(tractions, tractions%stage == s), sys, err, body_force, bl)
      else
        call applied_loads(mesh, sys%id, pack(tractions, tractions%stage == s), sys, err, body_load=bl)
      end if
      if (err%failed()) return
      ! the lifting: the stiffness of a plane cell is its law's, in plane strain or stress alike
      call element_table(model_of(mesh%axisymmetric, .true.), elems)
      call stiffness_and_lifting(mesh, laws, elems, sys, err, .false.)
      if (err%failed()) return
      call add_applied_loads(sys)
      sys%f_stage(:, s) = sys%f
      sys%u_stage(:, s) = sys%u_fixed
      sys%fa_stage(:, s) = sys%f_applied
      deallocate (sys%f, sys%u_fixed, sys%f_applied)
    end do
    call move_alloc(f_all, sys%f)
    call move_alloc(u_all, sys%u_fixed)
    call move_alloc(fa_all, sys%f_applied)
  end subroutine stage_loads

  !> The element loop: each cell's stiffness into the CSC values, and the lifting
  !! f -= K_fd u_d of its prescribed values, cell by cell (a mesh from a file is numbered
  !! for locality, so consecutive cells touch nearby columns). The values go where
  !! cell_row says when it is given (build_pattern's, a mesh that is not structured), else
  !! each column's rows are searched (the grid, whose regular pattern makes the search
  !! cheap). err = ERR_INPUT on a cell with a non-positive Jacobian, ERR_NUMERICAL on a
  !! coupling outside the pattern (an internal error).
  subroutine stiffness_and_lifting(mesh, laws, elems, sys, err, with_k, cell_row)
    type(mesh_t), intent(in) :: mesh
    type(elastic_law_t), intent(in) :: laws(:)
    type(element_slot_t), intent(in) :: elems(:)        ! the element of each cell shape
    type(body_system_t), intent(inout) :: sys
    type(error_t), intent(out) :: err
    logical, intent(in) :: with_k                       ! .false.: the lifting only
    integer(int16), allocatable, intent(in), optional :: cell_row(:, :, :)   ! build_pattern's
    integer :: c, nd, nvx, ndx, nsx
    integer, allocatable :: ldof(:)
    real(wp), allocatable :: ke(:, :)
    type(ke_cache_t) :: cache
    logical :: inside, mapped
    character(len=512) :: emsg

    call element_sizes(nvx, ndx, nsx)
    allocate (ldof(ndx), ke(ndx, ndx))
    mapped = .false.
    if (present(cell_row)) mapped = allocated(cell_row)
    call ke_cache_init(cache, maxval(abs(mesh%xy)))
    do c = 1, mesh%ncell
      call cell_stiffness(mesh, sys%id, c, laws, elems, cache, ke, nd, ldof, err)
      if (err%failed()) return
      inside = .true.
      if (with_k .and. mapped) then
        call scatter_cell(sys, ldof(1:nd), cell_row(:, :, c), ke)
      else if (with_k) then
        call scatter_element(sys, ldof(1:nd), ke, inside)
      end if
      if (.not. inside) then
        write (emsg, '(a,i0,a,i0,a)') 'body ', sys%id, ': internal error, cell ', c, &
          ' couples DOFs outside the stiffness pattern'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      call lift_prescribed(sys, ldof(1:nd), ke)
    end do
  end subroutine stiffness_and_lifting

  !> The stiffness of cell c (nd = its DOF count, ldof its global DOFs); err = ERR_INPUT,
  !! naming the cell's tag, when its Jacobian is not positive (inverted or degenerate).
  subroutine cell_stiffness(mesh, body_id, c, laws, elems, cache, ke, nd, ldof, err)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: body_id, c
    type(elastic_law_t), intent(in) :: laws(:)
    type(element_slot_t), intent(in) :: elems(:)
    type(ke_cache_t), intent(inout) :: cache
    real(wp), intent(out) :: ke(:, :)                  ! (element_sizes's nd, nd)
    integer, intent(out) :: nd, ldof(:)
    type(error_t), intent(inout) :: err
    real(wp) :: xe(NDIM, size(ldof)/NCOMP), minjac
    character(len=512) :: emsg
    nd = NCOMP*cell_vertices(mesh, c)
    call cell_coords(mesh, c, xe)
    associate (k => law_of(mesh, c))
      call elems(cell_element(mesh, c))%e%stiffness(xe, laws(k), k, ke, minjac, cache)
    end associate
    if (.not. (minjac > 0.0_wp)) then
      write (emsg, '(a,i0,a,i0,a)') 'body ', body_id, ': cell ', mesh%cell_tag(c), &
        ' has a non-positive Jacobian (inverted or degenerate element)'
      call err%set(ERR_INPUT, emsg)
      return
    end if
    call cell_dofs(mesh, c, ldof)
  end subroutine cell_stiffness

  !> Add the free-free block of an element stiffness to the CSC values. The element's
  !! DOFs are merged in increasing global (hence free) order with the sorted rows of
  !! each column. inside = .false. when a coupling is missing from the pattern.
  subroutine scatter_element(sys, ldof, ke, inside)
    type(body_system_t), intent(inout) :: sys
    integer, intent(in) :: ldof(:)                      ! (nd) global dofs of the element
    real(wp), intent(in) :: ke(:, :)
    logical, intent(out) :: inside
    integer :: nd, a, b, kk, fc, pos, pend, lfree(size(ldof)), perm(size(ldof))

    inside = .true.
    nd = size(ldof)
    ! Local dofs in increasing global order (insertion sort).
    do a = 1, nd
      perm(a) = a
    end do
    call sort_by_key(perm(1:nd), ldof)
    do a = 1, nd
      lfree(a) = sys%free_of(ldof(a))
    end do
    do b = 1, nd
      fc = lfree(b)
      if (fc == 0) cycle
      pos = sys%colptr(fc) + 1
      pend = sys%colptr(fc + 1)
      do kk = 1, nd
        a = perm(kk)
        if (lfree(a) == 0) cycle
        do while (sys%rowind(pos) /= lfree(a) - 1)
          pos = pos + 1
          if (pos > pend) then
            inside = .false.
            return
          end if
        end do
        sys%val(pos) = sys%val(pos) + ke(a, b)
      end do
    end do
  end subroutine scatter_element

  !> Add the free-free block of an element stiffness to the CSC values at the places
  !! the pattern recorded for the cell: vertex a's free rows follow the first cell_row(a, b)
  !! rows of each column of vertex b, x before y.
  subroutine scatter_cell(sys, ldof, cell_row, ke)
    type(body_system_t), intent(inout) :: sys
    integer, intent(in) :: ldof(:)                      ! (nd) global dofs of the element
    integer(int16), intent(in) :: cell_row(:, :)        ! (nv, nv) build_pattern's, of this cell
    real(wp), intent(in) :: ke(:, :)
    integer :: nd, a, b, pos, fr(size(ldof))

    nd = size(ldof)
    do a = 1, nd
      fr(a) = sys%free_of(ldof(a))
    end do
    do b = 1, nd
      if (fr(b) == 0) cycle
      do a = 1, nd, 2
        pos = sys%colptr(fr(b)) + cell_row((a + 1)/2, (b + 1)/2)
        if (fr(a) > 0) then
          pos = pos + 1
          sys%val(pos) = sys%val(pos) + ke(a, b)
        end if
        if (fr(a + 1) > 0) then
          pos = pos + 1
          sys%val(pos) = sys%val(pos) + ke(a + 1, b)
        end if
      end do
    end do
  end subroutine scatter_cell

  !> Lifting of an element's prescribed values: f(free) -= K_fd u_d, skipped when all
  !! its prescribed values are 0.
  subroutine lift_prescribed(sys, ldof, ke)
    type(body_system_t), intent(inout) :: sys
    integer, intent(in) :: ldof(:)                      ! (nd) global dofs of the element
    real(wp), intent(in) :: ke(:, :)
    integer :: nd, a, fa
    real(wp) :: ue(size(ldof))
    logical :: lift

    nd = size(ldof)
    lift = .false.
    do a = 1, nd
      if (sys%free_of(ldof(a)) == 0) then
        ue(a) = sys%u_fixed(ldof(a))
        if (ue(a) /= 0.0_wp) lift = .true.
      else
        ue(a) = 0.0_wp
      end if
    end do
    if (.not. lift) return
    do a = 1, nd
      fa = sys%free_of(ldof(a))
      if (fa == 0) cycle
      sys%f(fa) = sys%f(fa) - dot_product(ke(a, 1:nd), ue(1:nd))
    end do
  end subroutine lift_prescribed

  !> f += the applied loads at the free DOFs.
  subroutine add_applied_loads(sys)
    type(body_system_t), intent(inout) :: sys
    integer :: p
    do p = 1, sys%n
      sys%f(p) = sys%f(p) + sys%f_applied(sys%dof_of(p))
    end do
  end subroutine add_applied_loads

  !> Infinity norm of K; the pattern is symmetric, so column sums are row sums.
  pure real(wp) function stiffness_norm(sys) result(k_norm)
    type(body_system_t), intent(in) :: sys
    integer :: p
    real(wp) :: colsum
    k_norm = 0.0_wp
    do p = 1, sys%n
      colsum = sum(abs(sys%val(sys%colptr(p) + 1:sys%colptr(p + 1))))
      k_norm = max(k_norm, colsum)
    end do
  end function stiffness_norm

  !> Full displacement vector from the free unknowns: u_full = u_fixed + scatter(u_free).
  subroutine expand(sys, u_free, u_full)
    type(body_system_t), intent(in) :: sys   !< the body's system
    real(wp), intent(in) :: u_free(:)        !< (n) free displacements [length]
    real(wp), intent(out) :: u_full(:)       !< (ndof) all displacements [length]
    integer :: p
    u_full(1:sys%ndof) = sys%u_fixed
    do p = 1, sys%n
      u_full(sys%dof_of(p)) = u_free(p)
    end do
  end subroutine expand

  !> r = K_full u_full - f_full over all DOFs, by an element loop. At prescribed DOFs
  !! r is the reaction force that the supports exert on the body [force].
  subroutine residual_full(mesh, body, plane_strain, u_full, f_full, r, mag)
    type(mesh_t), intent(in) :: mesh         !< the body's mesh
    type(body_cfg_t), intent(in) :: body     !< material
    logical, intent(in) :: plane_strain      !< .true. plane strain, .false. plane stress
    real(wp), intent(in) :: u_full(:)        !< (ndof) displacements [length]
    real(wp), intent(in) :: f_full(:)        !< (ndof) nodal loads [force]
    real(wp), intent(out) :: r(:)            !< (ndof) residual [force]
    !> (ndof) optional: sum over the cells of |ke_ij u_j| at each DOF, the size of the terms
    !! that K u adds up (its rounding is eps times that, however much they cancel) [force]
    real(wp), intent(out), optional :: mag(:)
    integer :: c, nd, i, nvx, ndx, nsx
    integer, allocatable :: ldof(:)
    real(wp), allocatable :: xe(:, :), ke(:, :), ue(:)
    real(wp) :: minjac
    type(ke_cache_t) :: cache
    type(elastic_law_t), allocatable :: laws(:)
    type(element_slot_t) :: elems(NSHAPE)

    laws = body_laws(body, plane_strain)
    call element_table(model_of(mesh%axisymmetric, plane_strain), elems)
    call element_sizes(nvx, ndx, nsx)
    allocate (ldof(ndx), xe(NDIM, nvx), ke(ndx, ndx), ue(ndx))
    call ke_cache_init(cache, maxval(abs(mesh%xy)))
    r(1:NCOMP*mesh%nnode) = 0.0_wp
    if (present(mag)) mag(1:NCOMP*mesh%nnode) = 0.0_wp
    do c = 1, mesh%ncell
      nd = NCOMP*cell_vertices(mesh, c)
      call cell_coords(mesh, c, xe)
      call cell_dofs(mesh, c, ldof)
      associate (k => law_of(mesh, c))
        call elems(cell_element(mesh, c))%e%stiffness(xe, laws(k), k, ke, minjac, cache)
      end associate
      ue(1:nd) = u_full(ldof(1:nd))
      r(ldof(1:nd)) = r(ldof(1:nd)) + matmul(ke(1:nd, 1:nd), ue(1:nd))
      if (present(mag)) then
        do i = 1, nd
          mag(ldof(i)) = mag(ldof(i)) + sum(abs(ke(i, 1:nd)*ue(1:nd)))
        end do
      end if
    end do
    r(1:NCOMP*mesh%nnode) = r(1:NCOMP*mesh%nnode) - f_full(1:NCOMP*mesh%nnode)
  end subroutine residual_full

  !> The forces the supports exert on the body at its nodes: K u - f at the prescribed DOFs
  !! (residual_full with the applied loads f), 0 at the free ones and at the fixing DOFs of a
  !! body held only by contact (no support there: its residual is the body's equilibrium
  !! error, of the order of rounding). With the applied loads and
  !! the contact forces they balance the body: K u sums to zero over each component.
  subroutine support_reactions(mesh, body, plane_strain, sys, u_full, f_applied, r, mag)
    type(mesh_t), intent(in) :: mesh            !< the body's mesh
    type(body_cfg_t), intent(in) :: body        !< material
    logical, intent(in) :: plane_strain         !< .true. plane strain, .false. plane stress
    type(body_system_t), intent(in) :: sys      !< its DOF numbering (free_of)
    real(wp), intent(in) :: u_full(:)           !< (ndof) displacements [length]
    real(wp), intent(in) :: f_applied(:)        !< (ndof) the applied nodal loads [force]
    real(wp), intent(out) :: r(:)               !< (ndof) reactions [force]
    real(wp), intent(out), optional :: mag(:)   !< (ndof) the size of K u's terms (residual_full)
    call residual_full(mesh, body, plane_strain, u_full, f_applied, r, mag)
    where (sys%free_of(1:NCOMP*mesh%nnode) /= 0) r(1:NCOMP*mesh%nnode) = 0.0_wp
    if (allocated(sys%fixing)) r(sys%fixing) = 0.0_wp
  end subroutine support_reactions

  !> Nodal stresses: the unweighted average over the cells around each node of the cell
  !! value (Q1: at the cell centre; P1: the constant value), and the von Mises stress of
  !! the 3D state (sxx, syy, szz, sxy).
  subroutine nodal_stress(mesh, body, plane_strain, u_full, sigma, von_mises)
    type(mesh_t), intent(in) :: mesh            !< the body's mesh
    type(body_cfg_t), intent(in) :: body        !< material
    logical, intent(in) :: plane_strain         !< .true. plane strain, .false. plane stress
    real(wp), intent(in) :: u_full(:)           !< (ndof) displacements [length]
    !> (4, nnode) sxx, syy, sxy, szz [stress]; szz = nu (sxx + syy) in plane strain, 0 in plane stress
    real(wp), intent(out) :: sigma(:, :)
    real(wp), intent(out) :: von_mises(:)       !< (nnode) von Mises stress [stress]
    integer :: c, a, k, nd, law, nvx, ndx, nsx
    integer, allocatable :: cnt(:), ldof(:)
    real(wp), allocatable :: xe(:, :), ue(:), cs(:)
    real(wp) :: sxx, syy, sxy, szz
    type(elastic_law_t), allocatable :: laws(:)
    type(element_slot_t) :: elems(NSHAPE)

    laws = body_laws(body, plane_strain)
    call element_table(model_of(mesh%axisymmetric, plane_strain), elems)
    call element_sizes(nvx, ndx, nsx)
    allocate (ldof(ndx), xe(NDIM, nvx), ue(ndx), cs(nsx))
    allocate (cnt(mesh%nnode))
    cnt = 0
    sigma(:, 1:mesh%nnode) = 0.0_wp
    do c = 1, mesh%ncell
      nd = NCOMP*cell_vertices(mesh, c)
      call cell_coords(mesh, c, xe)
      call cell_dofs(mesh, c, ldof)
      ue(1:nd) = u_full(ldof(1:nd))
      law = law_of(mesh, c)
      call elems(cell_element(mesh, c))%e%stress(xe, ue, laws(law), cs)
      do a = 1, nd/NCOMP
        k = mesh%cells(a, c)
        sigma(:, k) = sigma(:, k) + cs
        cnt(k) = cnt(k) + 1
      end do
    end do
    do k = 1, mesh%nnode
      if (cnt(k) > 0) sigma(:, k) = sigma(:, k)/real(cnt(k), wp)
      if (NDIM == 3) then     ! sxx, syy, szz, syz, sxz, sxy
        von_mises(k) = sqrt(0.5_wp*((sigma(1, k) - sigma(2, k))**2 + (sigma(2, k) - sigma(3, k))**2 + &
                                    (sigma(3, k) - sigma(1, k))**2) + 3.0_wp*sum(sigma(4:6, k)**2))
        cycle
      end if
      sxx = sigma(1, k)
      syy = sigma(2, k)
      sxy = sigma(3, k)
      szz = sigma(4, k)
      von_mises(k) = sqrt(0.5_wp*((sxx - syy)**2 + (syy - szz)**2 + (szz - sxx)**2) + 3.0_wp*sxy**2)
    end do
  end subroutine nodal_stress

  !> y = K x on the free DOFs (linop's csc_symv: the pattern is symmetric, column j is row j).
  subroutine csc_matvec(sys, x, y)
    type(body_system_t), intent(in) :: sys   !< the body's system
    real(wp), intent(in) :: x(:)             !< (n) [length]
    real(wp), intent(out) :: y(:)            !< (n) [force]
    call csc_symv(sys%n, sys%colptr, sys%rowind, sys%val, x, y)
  end subroutine csc_matvec

  ! ---------------------------------------------------------------------------------
  ! Cells and sides
  ! ---------------------------------------------------------------------------------

  !> Vertex coordinates of cell c (columns past its vertices are 0).
  pure subroutine cell_coords(mesh, c, xe)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: c
    real(wp), intent(out) :: xe(:, :)       ! (NDIM, element_sizes's nv)
    integer :: a
    xe = 0.0_wp
    do a = 1, cell_vertices(mesh, c)
      xe(:, a) = mesh%xy(:, mesh%cells(a, c))
    end do
  end subroutine cell_coords

  !> Global dofs of cell c, interleaved by vertex (entries past 2*mesh%nvert are 0).
  pure subroutine cell_dofs(mesh, c, ldof)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: c
    integer, intent(out) :: ldof(:)         ! (element_sizes's nd)
    integer :: a, cc
    ldof = 0
    do a = 1, cell_vertices(mesh, c)
      do cc = 1, NCOMP
        ldof(node_dof(a, cc)) = node_dof(mesh%cells(a, c), cc)
      end do
    end do
  end subroutine cell_dofs

  !> Add the consistent nodal loads of a linear traction on one side to f, edge by edge.
  subroutine add_traction(mesh, tr, f)
    type(mesh_t), intent(in) :: mesh
    type(traction_cfg_t), intent(in) :: tr
    real(wp), intent(inout) :: f(:)
    integer, allocatable :: nodes(:)
    integer :: e, na, nb, coord
    real(wp) :: fe(2, 2)

    call side_nodes(mesh, tr%side, nodes)
    coord = 1
    if (tr%side == SIDE_LEFT .or. tr%side == SIDE_RIGHT) coord = 2
    do e = 1, size(nodes) - 1
      na = nodes(e)
      nb = nodes(e + 1)
      fe(:, 1) = f(2*na - 1:2*na)
      fe(:, 2) = f(2*nb - 1:2*nb)
      call edge_traction(mesh%xy(:, na), mesh%xy(:, nb), coord, tr%t0(1:2), tr%t1(1:2), fe, mesh%axisymmetric)
      f(2*na - 1:2*na) = fe(:, 1)
      f(2*nb - 1:2*nb) = fe(:, 2)
    end do
  end subroutine add_traction

  !> Add the consistent nodal loads of t(x,y) = t0 + tx*x + ty*y - pressure*n on the edges
  !! of group g (n the edge's outward unit normal): exact for a traction linear along each
  !! straight edge, f_a += L/6 (2 t_a + t_b), f_b += L/6 (t_a + 2 t_b).
  subroutine add_group_traction(mesh, g, tr, f)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: g
    type(traction_cfg_t), intent(in) :: tr
    real(wp), intent(inout) :: f(:)
    integer :: e, na, nb
    real(wp) :: xa(2), xb(2), len, nrm(2), ta(2), tb(2)
    do e = 1, mesh%group(g)%nedge
      na = mesh%group(g)%edge(1, e)
      nb = mesh%group(g)%edge(2, e)
      xa = mesh%xy(:, na)
      xb = mesh%xy(:, nb)
      len = norm2(xb - xa)
      nrm = [xb(2) - xa(2), -(xb(1) - xa(1))]/len
      ta = tr%t0(1:2) + tr%tx(1:2)*xa(1) + tr%ty(1:2)*xa(2) - tr%pressure*nrm
      tb = tr%t0(1:2) + tr%tx(1:2)*xb(1) + tr%ty(1:2)*xb(2) - tr%pressure*nrm
      if (mesh%axisymmetric) then
        ! per radian: int N t r ds, the cubic integrand by 2-point Gauss (exact)
        call radial_edge_load(xa, xb, ta, tb, f(2*na - 1:2*na), f(2*nb - 1:2*nb))
      else
        f(2*na - 1:2*na) = f(2*na - 1:2*na) + len/6.0_wp*(2.0_wp*ta + tb)
        f(2*nb - 1:2*nb) = f(2*nb - 1:2*nb) + len/6.0_wp*(ta + 2.0_wp*tb)
      end if
    end do
  end subroutine add_group_traction

  !> Add the consistent nodal loads of t = t0 - pressure n on the faces of group g (n each
  !! face's outward unit normal; a bilinear face's normal varies over it: its traction is t0
  !! plus the pressure on its area-weighted mean normal, exact on a planar face).
  subroutine add_face_traction(mesh, g, tr, f)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: g
    type(traction_cfg_t), intent(in) :: tr
    real(wp), intent(inout) :: f(:)
    integer :: e, nv, a, k
    real(wp) :: xf(3, 4), an(3), t(3), fe(3, 4)
    do e = 1, mesh%group(g)%nedge
      nv = count(mesh%group(g)%edge(:, e) > 0)
      xf = 0.0_wp
      do a = 1, nv
        xf(:, a) = mesh%xy(:, mesh%group(g)%edge(a, e))
      end do
      call face_area_normal(nv, xf, an)
      t = tr%t0 - tr%pressure*an/norm2(an)
      call face_traction(nv, xf, t, fe)
      do a = 1, nv
        k = mesh%group(g)%edge(a, e)
        f(node_dof(k, 1):node_dof(k, 3)) = f(node_dof(k, 1):node_dof(k, 3)) + fe(:, a)
      end do
    end do
  end subroutine add_face_traction

  !> Per radian, the nodal loads of a traction linear along the straight edge xa-xb (ta at
  !! xa, tb at xb) on a meridian section: int N t r ds, r = x, by 2-point Gauss (exact).
  pure subroutine radial_edge_load(xa, xb, ta, tb, fa, fb)
    real(wp), intent(in) :: xa(2), xb(2), ta(2), tb(2)
    real(wp), intent(inout) :: fa(2), fb(2)
    real(wp), parameter :: gp = 0.577350269189625764509148780502_wp
    real(wp) :: len, wa, wb, r, t(2)
    integer :: ig
    len = norm2(xb - xa)
    do ig = -1, 1, 2
      wa = 0.5_wp*(1.0_wp - ig*gp)
      wb = 0.5_wp*(1.0_wp + ig*gp)
      r = wa*xa(1) + wb*xb(1)
      t = (wa*ta + wb*tb)*r
      fa = fa + 0.5_wp*len*wa*t
      fb = fb + 0.5_wp*len*wb*t
    end do
  end subroutine radial_edge_load

  !> Add the consistent nodal loads of a body force b [force/length^3], constant in the cells
  !! of each law, to f: w(a) b per cell (element_shape_integrals), exact on any Q1 or P1 cell.
  subroutine add_constant_body_force(mesh, b, f)
    type(mesh_t), intent(in) :: mesh
    real(wp), intent(in) :: b(:, :)        ! (2, laws) the force in the cells of each law
    real(wp), intent(inout) :: f(:)
    integer :: c, a, k, law, nvx, ndx, nsx
    real(wp), allocatable :: xe(:, :), w(:)
    type(element_slot_t) :: elems(NSHAPE)
    call element_table(model_of(mesh%axisymmetric, .true.), elems)   ! loads: plane strain or stress alike
    call element_sizes(nvx, ndx, nsx)
    allocate (xe(NDIM, nvx), w(nvx))
    do c = 1, mesh%ncell
      law = law_of(mesh, c)
      if (all(b(:, law) == 0.0_wp)) cycle
      call cell_coords(mesh, c, xe)
      call elems(cell_element(mesh, c))%e%shape_integrals(xe, w)
      do a = 1, cell_vertices(mesh, c)
        k = mesh%cells(a, c)
        f(node_dof(k, 1):node_dof(k, NCOMP)) = f(node_dof(k, 1):node_dof(k, NCOMP)) + w(a)*b(:, law)
      end do
    end do
  end subroutine add_constant_body_force

  !> Add the consistent nodal loads of a body force density to f, cell by cell.
  subroutine add_body_force(mesh, bf, f)
    type(mesh_t), intent(in) :: mesh
    procedure(body_force_fn) :: bf
    real(wp), intent(inout) :: f(:)
    integer :: c, a, k, nvx, ndx, nsx
    real(wp), allocatable :: xe(:, :), fe(:, :)
    type(element_slot_t) :: elems(NSHAPE)

    call element_table(model_of(mesh%axisymmetric, .true.), elems)   ! loads: plane strain or stress alike
    call element_sizes(nvx, ndx, nsx)
    allocate (xe(NDIM, nvx), fe(NCOMP, nvx))
    fe = 0.0_wp
    do c = 1, mesh%ncell
      call cell_coords(mesh, c, xe)
      do a = 1, cell_vertices(mesh, c)
        k = mesh%cells(a, c)
        fe(:, a) = f(node_dof(k, 1):node_dof(k, NCOMP))
      end do
      call elems(cell_element(mesh, c))%e%body_force(xe, bf, fe)
      do a = 1, cell_vertices(mesh, c)
        k = mesh%cells(a, c)
        f(node_dof(k, 1):node_dof(k, NCOMP)) = fe(:, a)
      end do
    end do
  end subroutine add_body_force

end module assembly
