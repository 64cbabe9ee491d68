!> Structured meshes of a rectangular body: nodes on a uniform (nx+1) x (ny+1) grid,
!! bilinear quadrilaterals (Q1) or linear triangles (P1, two per grid cell).
!!
!! Numbering: node (i,j), i = 0..nx along x, j = 0..ny along y, has id 1 + i + j*(nx+1).
!! Grid cell (i,j), i = 0..nx-1, j = 0..ny-1, is cell 1 + i + j*nx for Q1, with its nodes
!! counter-clockwise from the lower-left corner: (i,j), (i+1,j), (i+1,j+1), (i,j+1).
!! For P1 each grid cell c is split along its diagonal from the lower-left to the
!! upper-right corner, (i,j)-(i+1,j+1), into triangle 2c-1 = (i,j), (i+1,j), (i+1,j+1)
!! (below the diagonal) and triangle 2c = (i,j), (i+1,j+1), (i,j+1) (above it), both
!! counter-clockwise.
module mesh
  use kinds, only: wp
  use config, only: body_cfg_t, ELEM_Q1, ELEM_P1, SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP
  implicit none (type, external)
  private

  public :: mesh_build, side_nodes, node_id

  !> A structured mesh of one rectangular body.
  type, public :: mesh_t
    integer :: element = ELEM_Q1          !< ELEM_Q1 or ELEM_P1 (module config)
    integer :: nx = 0                     !< grid cells along x
    integer :: ny = 0                     !< grid cells along y
    integer :: nnode = 0                  !< (nx+1)*(ny+1)
    integer :: ncell = 0                  !< nx*ny (Q1) or 2*nx*ny (P1)
    integer :: nvert = 0                  !< vertices per cell: 4 (Q1) or 3 (P1)
    real(wp) :: x0 = 0.0_wp               !< lower-left corner x [length]
    real(wp) :: y0 = 0.0_wp               !< lower-left corner y [length]
    real(wp) :: width = 0.0_wp            !< extent in x [length]
    real(wp) :: height = 0.0_wp           !< extent in y [length]
    real(wp), allocatable :: xy(:, :)     !< (2, nnode) node coordinates [length]
    integer, allocatable :: cells(:, :)   !< (nvert, ncell) 1-based node ids, counter-clockwise
  end type mesh_t

contains

  !> Id of grid node (i,j), i = 0..nx, j = 0..ny.
  pure integer function node_id(mesh, i, j)
    type(mesh_t), intent(in) :: mesh  !< the mesh
    integer, intent(in) :: i          !< grid index along x, 0..nx
    integer, intent(in) :: j          !< grid index along y, 0..ny
    node_id = 1 + i + j*(mesh%nx + 1)
  end function node_id

  !> Build the structured mesh of a body (its rectangle, nx x ny grid cells and element).
  !! On a bad body (nx or ny < 1, non-positive extent, unknown element) the mesh is left
  !! empty (nnode = 0) and, if present, `info` is non-zero with a sentence in `msg`.
  subroutine mesh_build(mesh, body, info, msg)
    type(mesh_t), intent(out) :: mesh                  !< the mesh built
    type(body_cfg_t), intent(in) :: body               !< geometry, grid and element of the body
    integer, intent(out), optional :: info             !< 0 on success
    character(len=*), intent(out), optional :: msg     !< error sentence when info /= 0
    integer :: i, j, c, n00, n10, n01, n11, stat
    character(len=256) :: err

    stat = 0
    err = ''
    if (body%nx < 1 .or. body%ny < 1) then
      stat = 1
      write (err, '(a,i0,a,i0,a,i0,a)') 'body ', body%id, ': the grid needs nx, ny >= 1 (got ', &
        body%nx, ' x ', body%ny, ')'
    else if (.not. (body%width > 0.0_wp .and. body%height > 0.0_wp)) then
      stat = 2
      write (err, '(a,i0,a,es12.4,a,es12.4,a)') 'body ', body%id, &
        ': width and height must be positive (got ', body%width, ', ', body%height, ')'
    else if (body%element /= ELEM_Q1 .and. body%element /= ELEM_P1) then
      stat = 3
      write (err, '(a,i0,a,i0)') 'body ', body%id, ': unknown element code ', body%element
    end if
    if (present(info)) info = stat
    if (present(msg)) msg = err
    if (stat /= 0) return

    mesh%element = body%element
    mesh%nx = body%nx
    mesh%ny = body%ny
    mesh%x0 = body%x0
    mesh%y0 = body%y0
    mesh%width = body%width
    mesh%height = body%height
    mesh%nnode = (mesh%nx + 1)*(mesh%ny + 1)
    allocate (mesh%xy(2, mesh%nnode))
    do j = 0, mesh%ny
      do i = 0, mesh%nx
        mesh%xy(1, node_id(mesh, i, j)) = mesh%x0 + mesh%width*real(i, wp)/real(mesh%nx, wp)
        mesh%xy(2, node_id(mesh, i, j)) = mesh%y0 + mesh%height*real(j, wp)/real(mesh%ny, wp)
      end do
    end do

    if (mesh%element == ELEM_Q1) then
      mesh%nvert = 4
      mesh%ncell = mesh%nx*mesh%ny
    else
      mesh%nvert = 3
      mesh%ncell = 2*mesh%nx*mesh%ny
    end if
    allocate (mesh%cells(mesh%nvert, mesh%ncell))
    do j = 0, mesh%ny - 1
      do i = 0, mesh%nx - 1
        c = 1 + i + j*mesh%nx
        n00 = node_id(mesh, i, j)
        n10 = n00 + 1
        n01 = n00 + mesh%nx + 1
        n11 = n01 + 1
        if (mesh%element == ELEM_Q1) then
          mesh%cells(:, c) = [n00, n10, n11, n01]
        else
          ! Diagonal from the lower-left to the upper-right corner.
          mesh%cells(:, 2*c - 1) = [n00, n10, n11]
          mesh%cells(:, 2*c) = [n00, n11, n01]
        end if
      end do
    end do
  end subroutine mesh_build

  !> The nodes on one side of the mesh, ordered by increasing s (x on bottom/top,
  !! y on left/right), corners included. An unknown side gives an empty list.
  subroutine side_nodes(mesh, side, nodes)
    type(mesh_t), intent(in) :: mesh                 !< the mesh
    integer, intent(in) :: side                      !< SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM or SIDE_TOP
    integer, allocatable, intent(out) :: nodes(:)    !< node ids along the side
    integer :: k

    select case (side)
    case (SIDE_LEFT)
      nodes = [(node_id(mesh, 0, k), k=0, mesh%ny)]
    case (SIDE_RIGHT)
      nodes = [(node_id(mesh, mesh%nx, k), k=0, mesh%ny)]
    case (SIDE_BOTTOM)
      nodes = [(node_id(mesh, k, 0), k=0, mesh%nx)]
    case (SIDE_TOP)
      nodes = [(node_id(mesh, k, mesh%ny), k=0, mesh%nx)]
    case default
      allocate (nodes(0))
    end select
  end subroutine side_nodes

end module mesh
