!> The supports of one body: which DOFs its side conditions (a rectangle's sides) and its
!! &boundary conditions (named groups) prescribe, with their values, and the numbering of
!! the DOFs left free (body_system_t's ndof, u_fixed, n, free_of, dof_of).
module supports
  use kinds, only: wp
  use space, only: NDIM, NCOMP, node_dof
  use strings, only: i2s
  use config, only: body_cfg_t, boundary_cfg_t, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT, side_axis
  use mesh, only: mesh_t, side_nodes, group_index, group_names, group_nodes
  use body_system, only: body_system_t
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  public :: prescribed_dofs, group_conditions, unknown_group, number_free_dofs

contains

  !> Which DOFs the side conditions prescribe (`prescribed`), their values and load stages
  !! (sys%ndof, sys%u_fixed, sys%dof_stage; a support's stage is 0). Sides are visited in
  !! SIDE_* order; a corner shared by two sides gets
  !! the union of their constraints, and where both prescribe the same component with
  !! different values the later side in SIDE_* order (left, right, bottom, top) wins.
  !! `u_prescribed`, where given, replaces the values at every prescribed DOF.
  subroutine prescribed_dofs(mesh, body, prescribed, sys, u_prescribed)
    type(mesh_t), intent(in) :: mesh                    !< the body's mesh
    type(body_cfg_t), intent(in) :: body                !< its side conditions (bc, u_side)
    logical, allocatable, intent(out) :: prescribed(:)  !< (ndof) whether each DOF is prescribed
    type(body_system_t), intent(inout) :: sys           !< gets ndof and u_fixed
    real(wp), intent(in), optional :: u_prescribed(:)   !< (ndof) values replacing the side values [length]
    integer, allocatable :: nodes(:)
    integer :: side, k, cc

    sys%ndof = NCOMP*mesh%nnode
    allocate (prescribed(sys%ndof), sys%u_fixed(sys%ndof), sys%dof_stage(sys%ndof))
    prescribed = .false.
    sys%u_fixed = 0.0_wp
    sys%dof_stage = 0
    do side = 1, 2*NDIM
      call side_nodes(mesh, side, nodes)
      select case (body%bc(side))
      case (BC_CLAMPED)
        do k = 1, size(nodes)
          do cc = 1, NCOMP
            prescribed(node_dof(nodes(k), cc)) = .true.
            sys%u_fixed(node_dof(nodes(k), cc)) = 0.0_wp
            sys%dof_stage(node_dof(nodes(k), cc)) = 0
          end do
        end do
      case (BC_ROLLER)
        cc = side_axis(side)
        do k = 1, size(nodes)
          prescribed(node_dof(nodes(k), cc)) = .true.
          sys%u_fixed(node_dof(nodes(k), cc)) = 0.0_wp
          sys%dof_stage(node_dof(nodes(k), cc)) = 0
        end do
      case (BC_DISPLACEMENT)
        do k = 1, size(nodes)
          do cc = 1, NCOMP
            prescribed(node_dof(nodes(k), cc)) = .true.
            sys%u_fixed(node_dof(nodes(k), cc)) = body%u_side(cc, side)
            sys%dof_stage(node_dof(nodes(k), cc)) = body%side_stage(side)
          end do
        end do
      case default   ! BC_FREE, BC_CONTACT: nothing
      end select
    end do
    if (present(u_prescribed)) then
      where (prescribed) sys%u_fixed = u_prescribed
      where (prescribed .and. sys%dof_stage == 0) sys%dof_stage = 1
    end if
  end subroutine prescribed_dofs

  !> The &boundary conditions of this body: the components given are prescribed on every
  !! node of the group (a later condition overrides an earlier value). err (ERR_INPUT) when
  !! the group is not one of the body's, naming the body, where the deck gave the condition,
  !! the group and the groups there are.
  subroutine group_conditions(mesh, body_id, boundaries, prescribed, sys, err)
    type(mesh_t), intent(in) :: mesh                   !< the body's mesh
    integer, intent(in) :: body_id                     !< the body (conditions of the other are skipped)
    type(boundary_cfg_t), intent(in) :: boundaries(:)  !< the deck's &boundary conditions
    logical, intent(inout) :: prescribed(:)            !< (ndof) whether each DOF is prescribed
    type(body_system_t), intent(inout) :: sys          !< its u_fixed gets the values
    type(error_t), intent(out) :: err                  !< ERR_INPUT: an unknown group
    integer :: i, g, k, cc, dof
    integer, allocatable :: nodes(:)
    character(len=:), allocatable :: why

    do i = 1, size(boundaries)
      if (boundaries(i)%body /= body_id) cycle
      g = group_index(mesh, boundaries(i)%group)
      if (g == 0) then
        call unknown_group(mesh, boundaries(i)%group, why)
        call err%set(ERR_INPUT, 'body '//i2s(body_id)//': '//trim(boundaries(i)%origin)//': '//why)
        return
      end if
      call group_nodes(mesh, g, nodes)
      do k = 1, size(nodes)
        do cc = 1, NCOMP
          if (.not. boundaries(i)%fix(cc)) cycle
          dof = node_dof(nodes(k), cc)
          prescribed(dof) = .true.
          sys%u_fixed(dof) = boundaries(i)%u(cc)
          sys%dof_stage(dof) = merge(boundaries(i)%stage, 0, boundaries(i)%u(cc) /= 0.0_wp)
        end do
      end do
    end do
  end subroutine group_conditions

  !> The sentence for a group name the body's mesh does not have (in space: no face, and
  !! the physical surfaces of its volume mesh's file).
  subroutine unknown_group(mesh, name, s)
    type(mesh_t), intent(in) :: mesh      !< the body's mesh
    character(len=*), intent(in) :: name  !< the group name it lacks
    character(len=:), allocatable, intent(out) :: s   !< the sentence
    character(len=:), allocatable :: src, names
    src = 'the rectangle'
    if (mesh%box) src = 'the box'
    if (allocated(mesh%source)) then
      if (len(mesh%source) > 0) src = mesh%source
    end if
    if (NDIM == 3) then
      call group_names(mesh, names)
      s = 'group '''//trim(name)//''' has no face on the boundary of this body ('//src// &
          '); its groups are '//names
      if (allocated(mesh%file_groups) .and. .not. mesh%box) then
        if (len_trim(mesh%file_groups) > 0) s = s//' (physical surfaces of the file: '//trim(mesh%file_groups)//')'
      end if
      return
    end if
    call group_names(mesh, names)
    s = 'group '''//trim(name)//''' has no edge on the boundary of this body ('//src// &
        '); its groups are '//names
    if (allocated(mesh%file_groups) .and. .not. mesh%structured) then
      if (len_trim(mesh%file_groups) > 0) s = s//' (physical curves of the file: '//trim(mesh%file_groups)//')'
    end if
  end subroutine unknown_group

  !> Number the DOFs that are not prescribed 1..n in increasing global order
  !! (sys%n, sys%free_of, sys%dof_of).
  subroutine number_free_dofs(prescribed, sys)
    logical, intent(in) :: prescribed(:)       !< (ndof) whether each DOF is prescribed
    type(body_system_t), intent(inout) :: sys  !< gets n, free_of, dof_of
    integer :: k, n

    allocate (sys%free_of(sys%ndof))
    n = 0
    do k = 1, sys%ndof
      if (prescribed(k)) then
        sys%free_of(k) = 0
      else
        n = n + 1
        sys%free_of(k) = n
      end if
    end do
    sys%n = n
    allocate (sys%dof_of(n))
    do k = 1, sys%ndof
      if (sys%free_of(k) > 0) sys%dof_of(sys%free_of(k)) = k
    end do
  end subroutine number_free_dofs

end module supports
