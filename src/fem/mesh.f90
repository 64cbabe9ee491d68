!> The mesh of one body: a structured grid of a rectangle (mesh_build) or of a box
!! (box_build), or a general mesh read from a file (module gmsh_msh: 2D, or in a 3D run a
!! volume mesh of tetrahedra and hexahedra, module volume_topology), in one type.
!!
!! Structured meshes: nodes on a uniform (nx+1) x (ny+1) grid, bilinear quadrilaterals (Q1)
!! or linear triangles (P1, two per grid cell). Node (i,j), i = 0..nx along x, j = 0..ny
!! along y, has id 1 + i + j*(nx+1). Grid cell (i,j), i = 0..nx-1, j = 0..ny-1, is cell
!! 1 + i + j*nx for Q1, with its nodes counter-clockwise from the lower-left corner: (i,j),
!! (i+1,j), (i+1,j+1), (i,j+1). For P1 each grid cell c is split along its diagonal from the
!! lower-left to the upper-right corner, (i,j)-(i+1,j+1), into triangle 2c-1 = (i,j),
!! (i+1,j), (i+1,j+1) (below the diagonal) and triangle 2c = (i,j), (i+1,j+1), (i,j+1)
!! (above it), both counter-clockwise. A structured mesh has the groups 'left', 'right',
!! 'bottom' and 'top'.
!!
!! General meshes: cells of mixed types (`cell_type`), counter-clockwise after reading,
!! with the file's tags kept for messages, and named groups of boundary edges (`group`) on
!! which conditions and the contact surface are given; a group may also hold single nodes
!! (a Gmsh physical point, or the nodes of a physical curve inside the body), usable for
!! prescribed displacements only.
!!
!! Every group edge is a boundary edge of one cell, oriented counter-clockwise around the
!! body (the body on its left), so its outward normal is (dy, -dx)/length.
!!
!! A mesh read from a file is numbered for locality (nodes and cells along a space-filling
!! curve), not in the file's order; `file_node` and `file_cell` keep the file's, and every
!! per-node or per-cell output goes through `file_order` and `file_cells`, so that results
!! are written in the file's node and cell order.
module mesh
  use kinds, only: wp
  use space, only: node_dof, dof_node, dof_comp
  use strings, only: i2s
  use errors, only: error_t, ERR_INPUT
  use config, only: body_cfg_t, elastic_law_t, ELEM_Q1, ELEM_P1, ELEM_HEX8, ELEM_TET4, SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, &
                    SIDE_TOP, MAX_SIDES, side_names, shape_vertices
  implicit none (type, external)
  private

  public :: assign_cell_laws
  public :: mesh_build, box_build, box_node, side_nodes, node_id, group_index, group_names, group_nodes, &
            nodes_only, nodes_only_refusal, cell_element, cell_vertices, file_order, file_cells, file_dof

  !> A nodal field in the file's node order (the order of every per-node output).
  interface file_order
    module procedure file_order_1, file_order_2
  end interface file_order

  !> A named set of boundary facets of one body (in the plane edges: a Gmsh physical curve or
  !! a rectangle side; in space faces: a box side) and of single nodes (a Gmsh physical point,
  !! or where a physical curve runs inside the body: its nodes off the boundary edges).
  type, public :: edge_group_t
    character(len=:), allocatable :: name      !< the group's name (Gmsh physical name)
    integer :: nedge = 0                       !< facets (edges, faces) of this body in the group
    !> (nvf, nedge) node ids of each facet: an edge (nvf = 2) with the body on its left; a face
    !! of 3 or 4 nodes (nvf = 3 or 4; a triangle among quadrilaterals has a 0 in row 4)
    !! counter-clockwise seen from outside (the right-hand rule gives the outward normal)
    integer, allocatable :: edge(:, :)
    integer, allocatable :: cell(:)            !< (nedge) the cell each edge bounds
    integer :: nnode = 0                       !< single nodes of this body in the group
    integer, allocatable :: node(:)            !< (nnode) their node ids
    logical :: point = .false.                 !< a Gmsh physical point (nedge = 0)
  end type edge_group_t

  !> The body's cells in one physical surface of its mesh file other than the body's own
  !! (a region: a coating, a ply, an insert).
  type, public :: cell_group_t
    character(len=:), allocatable :: name      !< the physical surface's name
    integer, allocatable :: cell(:)            !< the body's cells in it
  end type cell_group_t

  !> The mesh of one body (structured or general).
  type, public :: mesh_t
    integer :: element = ELEM_Q1          !< ELEM_Q1, ELEM_P1 or (general meshes) ELEM_MIXED (module config)
    integer :: nx = 0                     !< grid cells along x (0 on a general mesh)
    integer :: ny = 0                     !< grid cells along y (0 on a general mesh)
    integer :: nz = 0                     !< a box's grid cells along z (0 otherwise)
    integer :: nnode = 0                  !< nodes: (nx+1)*(ny+1) on a grid
    integer :: ncell = 0                  !< cells: nx*ny (Q1) or 2*nx*ny (P1) on a grid
    integer :: nvert = 0                  !< vertices per cell: 4 (Q1, mixed) or 3 (P1)
    real(wp) :: x0 = 0.0_wp               !< lower-left corner x (of the bounding box) [length]
    real(wp) :: y0 = 0.0_wp               !< lower-left corner y (of the bounding box) [length]
    real(wp) :: width = 0.0_wp            !< extent in x [length]
    real(wp) :: height = 0.0_wp           !< extent in y [length]
    real(wp) :: z0 = 0.0_wp               !< a box's front z [length]
    real(wp) :: depth = 0.0_wp            !< a box's extent in z [length]
    real(wp), allocatable :: xy(:, :)     !< (NDIM, nnode) node coordinates [length]
    integer, allocatable :: cells(:, :)   !< (nvert, ncell) 1-based node ids, counter-clockwise
                                          !! (a triangle in a mixed mesh: cells(4, c) = 0); in
                                          !! space in Gmsh's order, positively oriented
    logical :: structured = .true.        !< built by mesh_build (nx, ny, x0... valid; a rectangle's grid)
    logical :: box = .false.              !< built by box_build (nx, ny, nz, x0... valid; not `structured`)
    !> a meridian section of a body of revolution about the y axis (x = r >= 0, y = z): its
    !! integrals are per radian, weighted by r, with the hoop strain ur/r (set by the driver)
    logical :: axisymmetric = .false.
    character(len=:), allocatable :: source  !< the mesh file ('' for a structured mesh)
    integer, allocatable :: cell_type(:)  !< (ncell) ELEM_Q1 or ELEM_P1 of each cell (in space ELEM_HEX8 or ELEM_TET4)
    integer, allocatable :: node_tag(:)   !< (nnode) the file's node tag (structured: the node id)
    integer, allocatable :: cell_tag(:)   !< (ncell) the file's element tag (structured: the cell id)
    !> (nnode) a mesh from a file: each node's place in the file's order (the body's nodes
    !! by increasing tag); unallocated: the nodes are in that order
    integer, allocatable :: file_node(:)
    !> (ncell) a mesh from a file: each cell's place in the file's order of the body's
    !! cells; unallocated: the cells are in that order
    integer, allocatable :: file_cell(:)
    integer :: nregion = 0                !< physical surfaces (volumes) other than the body's with cells of it
    type(cell_group_t), allocatable :: region(:)   !< (nregion) their cells
    !> (ncell) the elastic law of each cell (an index into body_cfg_t%law; set by the driver
    !! from the deck's regions); unallocated: law 1 everywhere
    integer, allocatable :: cell_law(:)
    integer :: ngroup = 0                 !< named edge groups of this body
    type(edge_group_t), allocatable :: group(:)   !< (ngroup) the groups
    !> every physical curve name of the file, then '; physical points: ' and every physical
    !! point name if there are any, for messages (a volume mesh: every physical surface name,
    !! then '; physical curves: ' and '; physical points: ' with theirs)
    character(len=:), allocatable :: file_groups
  end type mesh_t

contains

  !> The elastic law of each cell (mesh%cell_law) from the body's laws (body_cfg_t%law: 1 the
  !! body's own, then one per region, named by its physical surface): unallocated when the
  !! body has one law. ERR_INPUT (and the law's index in `failing_law`, for the caller to
  !! name the deck's region) for a region that is no physical surface of the body's cells, or
  !! a cell in two regions of different laws (stiffness or density).
  subroutine assign_cell_laws(mesh, body, err, failing_law)
    type(mesh_t), intent(inout) :: mesh               !< the body's mesh
    type(body_cfg_t), intent(in) :: body              !< its laws
    type(error_t), intent(out) :: err                 !< ERR_INPUT: why not
    integer, intent(out) :: failing_law               !< the law that fails (its region's), 0: none
    integer :: k, r, j, c
    character(len=:), allocatable :: names
    failing_law = 0
    if (allocated(mesh%cell_law)) deallocate (mesh%cell_law)
    if (.not. allocated(body%law)) return
    if (size(body%law) < 2) return
    allocate (mesh%cell_law(mesh%ncell))
    mesh%cell_law = 1
    do k = 2, size(body%law)
      r = 0
      do j = 1, mesh%nregion
        if (mesh%region(j)%name == trim(body%law(k)%region)) r = j
      end do
      if (r == 0 .and. trim(body%law(k)%region) == trim(body%region)) then
        call err%set(ERR_INPUT, "'"//trim(body%law(k)%region)//"' is the body's own physical surface: a "// &
                     'region is another physical surface holding some of its cells')
        failing_law = k
        return
      else if (r == 0) then
        names = ''
        do j = 1, mesh%nregion
          names = names//merge(', ', '  ', j > 1)//"'"//mesh%region(j)%name//"'"
        end do
        if (mesh%nregion == 0) then
          call err%set(ERR_INPUT, "the body's cells are in no physical surface '"//trim(body%law(k)%region)// &
                       "' (they are in no physical surface but the body's own)")
        else
          call err%set(ERR_INPUT, "the body's cells are in no physical surface '"//trim(body%law(k)%region)// &
                       "' (the physical surfaces holding its cells: "//trim(adjustl(names))//')')
        end if
        failing_law = k
        return
      end if
      do j = 1, size(mesh%region(r)%cell)
        c = mesh%region(r)%cell(j)
        if (mesh%cell_law(c) /= 1) then
          if (any(body%law(mesh%cell_law(c))%d /= body%law(k)%d) .or. &
              body%law(mesh%cell_law(c))%density /= body%law(k)%density) then
            call err%set(ERR_INPUT, 'cell '//i2s(mesh%cell_tag(c))//" is in region '"// &
                         trim(body%law(mesh%cell_law(c))%region)//"' and in region '"//trim(body%law(k)%region)// &
                         "', of different materials: a cell is of one material")
            failing_law = k
            return
          end if
        end if
        mesh%cell_law(c) = k
      end do
    end do
  end subroutine assign_cell_laws

  !> Id of grid node (i,j), i = 0..nx, j = 0..ny.
  pure integer function node_id(mesh, i, j)
    type(mesh_t), intent(in) :: mesh  !< the mesh
    integer, intent(in) :: i          !< grid index along x, 0..nx
    integer, intent(in) :: j          !< grid index along y, 0..ny
    node_id = 1 + i + j*(mesh%nx + 1)
  end function node_id

  !> The element of cell c (ELEM_Q1 or ELEM_P1).
  pure integer function cell_element(mesh, c)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    integer, intent(in) :: c           !< a cell, 1..ncell
    if (allocated(mesh%cell_type)) then
      cell_element = mesh%cell_type(c)
    else
      cell_element = mesh%element
    end if
  end function cell_element

  !> The number of vertices of cell c.
  pure integer function cell_vertices(mesh, c)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    integer, intent(in) :: c           !< a cell, 1..ncell
    cell_vertices = shape_vertices(cell_element(mesh, c))
  end function cell_vertices


  !> x (one column per node, nodes numbered as the mesh) with its columns in the file's
  !! node order.
  pure function file_order_2(mesh, x) result(y)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    real(wp), intent(in) :: x(:, :)    !< (:, nnode) a nodal field
    real(wp) :: y(size(x, 1), size(x, 2))
    if (allocated(mesh%file_node)) then
      y(:, mesh%file_node) = x
    else
      y = x
    end if
  end function file_order_2

  !> x (one value per node, nodes numbered as the mesh) in the file's node order.
  pure function file_order_1(mesh, x) result(y)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    real(wp), intent(in) :: x(:)       !< (nnode) a nodal field
    real(wp) :: y(size(x))
    if (allocated(mesh%file_node)) then
      y(mesh%file_node) = x
    else
      y = x
    end if
  end function file_order_1

  !> The cells in the file's cell order, their nodes numbered in the file's node order
  !! (a triangle's 4th vertex in a mixed mesh stays 0).
  pure function file_cells(mesh) result(cells)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    integer :: cells(size(mesh%cells, 1), size(mesh%cells, 2))
    integer :: c, a, k
    do c = 1, size(mesh%cells, 2)
      k = c
      if (allocated(mesh%file_cell)) k = mesh%file_cell(c)
      do a = 1, size(mesh%cells, 1)
        cells(a, k) = mesh%cells(a, c)
        if (allocated(mesh%file_node) .and. cells(a, k) > 0) cells(a, k) = mesh%file_node(cells(a, k))
      end do
    end do
  end function file_cells

  !> Global DOF `dof` (space's node_dof(k, c)) numbered by the file's node order.
  elemental integer function file_dof(mesh, dof)
    type(mesh_t), intent(in) :: mesh   !< the mesh
    integer, intent(in) :: dof         !< a global DOF, 1..NCOMP nnode
    file_dof = dof
    if (allocated(mesh%file_node)) file_dof = node_dof(mesh%file_node(dof_node(dof)), dof_comp(dof))
  end function file_dof

  !> Build the structured mesh of a body (its rectangle, nx x ny grid cells and element).
  !! On a bad body (nx or ny < 1, non-positive extent, unknown element) the mesh is left
  !! empty (nnode = 0) and, if present, `info` is non-zero with a sentence in `msg`.
  subroutine mesh_build(mesh, body, err)
    type(mesh_t), intent(out) :: mesh                  !< the mesh built
    type(body_cfg_t), intent(in) :: body               !< geometry, grid and element of the body
    type(error_t), intent(out) :: err                  !< a grid the rectangle cannot have (ERR_INPUT)
    integer :: i, j, c, n00, n10, n01, n11
    character(len=256) :: why

    why = ''
    if (body%nx < 1 .or. body%ny < 1) then
      write (why, '(a,i0,a,i0,a,i0,a)') 'body ', body%id, ': the grid needs nx, ny >= 1 (got ', &
        body%nx, ' x ', body%ny, ')'
    else if (.not. (body%width > 0.0_wp .and. body%height > 0.0_wp)) then
      write (why, '(a,i0,a,es12.4,a,es12.4,a)') 'body ', body%id, &
        ': width and height must be positive (got ', body%width, ', ', body%height, ')'
    else if (body%element /= ELEM_Q1 .and. body%element /= ELEM_P1) then
      write (why, '(a,i0,a,i0)') 'body ', body%id, ': unknown element code ', body%element
    end if
    if (len_trim(why) > 0) then
      call err%set(ERR_INPUT, trim(why))
      return
    end if

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
    mesh%structured = .true.
    mesh%source = ''
    allocate (mesh%cell_type(mesh%ncell), mesh%node_tag(mesh%nnode), mesh%cell_tag(mesh%ncell))
    mesh%cell_type = mesh%element
    mesh%node_tag = [(i, i=1, mesh%nnode)]
    mesh%cell_tag = [(i, i=1, mesh%ncell)]
    call side_groups(mesh)
  end subroutine mesh_build

  !> Id of node (i, j, k) of a box's grid, i = 0..nx, j = 0..ny, k = 0..nz: 1 + i + j (nx + 1)
  !! + k (nx + 1)(ny + 1).
  pure integer function box_node(mesh, i, j, k)
    type(mesh_t), intent(in) :: mesh  !< a box's mesh
    integer, intent(in) :: i, j, k    !< grid indices along x, y, z
    box_node = 1 + i + (mesh%nx + 1)*(j + (mesh%ny + 1)*k)
  end function box_node

  !> Build the mesh of a box body: [x0, x0 + width] x [y0, y0 + height] x [z0, z0 + depth] on an
  !! nx x ny x nz grid, each grid cell a trilinear hexahedron (element Q1: ELEM_HEX8, in Gmsh's
  !! vertex order) or six linear tetrahedra (P1: ELEM_TET4, the Kuhn split of elements_3d:
  !! kuhn_tets, all sharing the cell's diagonal from its lowest to its highest corner, so
  !! neighbouring cells' faces match). Grid cell (i, j, k) is hexahedron 1 + i + nx (j + ny k),
  !! or tetrahedra 6 (that - 1) + 1 .. 6. The six sides are the groups 'left', 'right',
  !! 'bottom', 'top', 'front' (z = z0), 'back' (z = z0 + depth), their faces oriented outward:
  !! quadrilaterals, or each grid face cut along its diagonal from its lowest to its highest
  !! grid corner into two triangles (the tetrahedra's faces). info /= 0 with msg on a bad grid.
  subroutine box_build(mesh, body, tets, err)
    type(mesh_t), intent(out) :: mesh                  !< the mesh built
    type(body_cfg_t), intent(in) :: body               !< the box's geometry, grid and element
    !> the six tetrahedra of a grid cell's eight vertices (elements_3d's kuhn_tets, passed in
    !! so that mesh does not depend on the element kernels)
    interface
      pure subroutine tets(v, t)
        integer, intent(in) :: v(8)
        integer, intent(out) :: t(4, 6)
      end subroutine tets
    end interface
    type(error_t), intent(out) :: err                  !< a grid the box cannot have (ERR_INPUT)
    integer :: i, j, k, c, v(8), t(4, 6)

    if (body%nx < 1 .or. body%ny < 1 .or. body%nz < 1) then
      call err%set(ERR_INPUT, 'body '//i2s(body%id)//': the grid needs nx, ny, nz >= 1 (got '//i2s(body%nx)// &
                   ' x '//i2s(body%ny)//' x '//i2s(body%nz)//')')
      return
    else if (.not. (body%width > 0.0_wp .and. body%height > 0.0_wp .and. body%depth > 0.0_wp)) then
      call err%set(ERR_INPUT, 'body '//i2s(body%id)//': width, height and depth must be positive')
      return
    else if (body%element /= ELEM_Q1 .and. body%element /= ELEM_P1) then
      call err%set(ERR_INPUT, 'body '//i2s(body%id)//': unknown element code '//i2s(body%element))
      return
    end if
    mesh%element = merge(ELEM_HEX8, ELEM_TET4, body%element == ELEM_Q1)
    mesh%nx = body%nx
    mesh%ny = body%ny
    mesh%nz = body%nz
    mesh%x0 = body%x0
    mesh%y0 = body%y0
    mesh%z0 = body%z0
    mesh%width = body%width
    mesh%height = body%height
    mesh%depth = body%depth
    mesh%nnode = (mesh%nx + 1)*(mesh%ny + 1)*(mesh%nz + 1)
    allocate (mesh%xy(3, mesh%nnode))
    do k = 0, mesh%nz
      do j = 0, mesh%ny
        do i = 0, mesh%nx
          mesh%xy(:, box_node(mesh, i, j, k)) = [mesh%x0 + mesh%width*real(i, wp)/real(mesh%nx, wp), &
                                                 mesh%y0 + mesh%height*real(j, wp)/real(mesh%ny, wp), &
                                                 mesh%z0 + mesh%depth*real(k, wp)/real(mesh%nz, wp)]
        end do
      end do
    end do
    mesh%nvert = shape_vertices(mesh%element)
    mesh%ncell = mesh%nx*mesh%ny*mesh%nz*merge(1, 6, mesh%element == ELEM_HEX8)
    allocate (mesh%cells(mesh%nvert, mesh%ncell))
    do k = 0, mesh%nz - 1
      do j = 0, mesh%ny - 1
        do i = 0, mesh%nx - 1
          c = 1 + i + mesh%nx*(j + mesh%ny*k)
          v = [box_node(mesh, i, j, k), box_node(mesh, i + 1, j, k), box_node(mesh, i + 1, j + 1, k), &
               box_node(mesh, i, j + 1, k), box_node(mesh, i, j, k + 1), box_node(mesh, i + 1, j, k + 1), &
               box_node(mesh, i + 1, j + 1, k + 1), box_node(mesh, i, j + 1, k + 1)]
          if (mesh%element == ELEM_HEX8) then
            mesh%cells(:, c) = v
          else
            call tets(v, t)
            mesh%cells(:, 6*(c - 1) + 1:6*c) = t
          end if
        end do
      end do
    end do
    mesh%structured = .false.
    mesh%box = .true.
    mesh%source = ''
    allocate (mesh%cell_type(mesh%ncell), mesh%node_tag(mesh%nnode), mesh%cell_tag(mesh%ncell))
    mesh%cell_type = mesh%element
    mesh%node_tag = [(i, i=1, mesh%nnode)]
    mesh%cell_tag = [(i, i=1, mesh%ncell)]
    call box_side_groups(mesh)
  end subroutine box_build

  !> The six sides of a box as face groups, each face counter-clockwise seen from outside:
  !! side s spans grid axes (p, q) with e_p x e_q its outward normal; its face at grid
  !! position (a, b) is (a, b), (a+1, b), (a+1, b+1), (a, b+1) in (p, q), or the two
  !! triangles of its cut from (a, b) to (a+1, b+1). The cell each face bounds is its
  !! hexahedron, or the tetrahedron holding the triangle.
  subroutine box_side_groups(mesh)
    type(mesh_t), intent(inout) :: mesh
    ! per side: the fixed axis and its grid index (0 or n), and the axes p, q
    integer, parameter :: fixed(6) = [1, 1, 2, 2, 3, 3], pax(6) = [3, 2, 1, 3, 2, 1], qax(6) = [2, 3, 3, 1, 1, 2]
    integer :: side, n(3), a, b, nf, f, ijk(3), corner(4), g(3)
    logical :: hex

    hex = mesh%element == ELEM_HEX8
    n = [mesh%nx, mesh%ny, mesh%nz]
    mesh%ngroup = MAX_SIDES
    allocate (mesh%group(MAX_SIDES))
    mesh%file_groups = 'left right bottom top front back'
    do side = 1, MAX_SIDES
      nf = n(pax(side))*n(qax(side))*merge(1, 2, hex)
      mesh%group(side)%name = trim(side_names(side))
      mesh%group(side)%nedge = nf
      allocate (mesh%group(side)%edge(merge(4, 3, hex), nf), mesh%group(side)%cell(nf))
      f = 0
      do b = 0, n(qax(side)) - 1
        do a = 0, n(pax(side)) - 1
          corner(1) = node_at(a, b)
          corner(2) = node_at(a + 1, b)
          corner(3) = node_at(a + 1, b + 1)
          corner(4) = node_at(a, b + 1)
          ! the grid cell behind the face
          g(pax(side)) = a
          g(qax(side)) = b
          g(fixed(side)) = merge(0, n(fixed(side)) - 1, mod(side, 2) == 1)
          if (hex) then
            f = f + 1
            mesh%group(side)%edge(:, f) = corner
            mesh%group(side)%cell(f) = 1 + g(1) + mesh%nx*(g(2) + mesh%ny*g(3))
          else
            f = f + 1
            mesh%group(side)%edge(:, f) = corner([1, 2, 3])
            mesh%group(side)%cell(f) = tet_of(1 + g(1) + mesh%nx*(g(2) + mesh%ny*g(3)), corner([1, 2, 3]))
            f = f + 1
            mesh%group(side)%edge(:, f) = corner([1, 3, 4])
            mesh%group(side)%cell(f) = tet_of(1 + g(1) + mesh%nx*(g(2) + mesh%ny*g(3)), corner([1, 3, 4]))
          end if
        end do
      end do
    end do

  contains

    !> The node at grid position (a, b) of the side: the fixed axis at 0 (odd sides) or n.
    integer function node_at(a, b)
      integer, intent(in) :: a, b
      ijk(pax(side)) = a
      ijk(qax(side)) = b
      ijk(fixed(side)) = merge(0, n(fixed(side)), mod(side, 2) == 1)
      node_at = box_node(mesh, ijk(1), ijk(2), ijk(3))
    end function node_at

    !> The tetrahedron of grid cell q holding the three nodes (0 if none: not a face of it).
    integer function tet_of(q, tri)
      integer, intent(in) :: q, tri(3)
      integer :: t, m
      tet_of = 0
      do t = 6*(q - 1) + 1, 6*q
        if (all([(any(mesh%cells(:, t) == tri(m)), m=1, 3)])) then
          tet_of = t
          return
        end if
      end do
    end function tet_of
  end subroutine box_side_groups

  !> The four sides of a structured mesh as edge groups 'left', 'right', 'bottom', 'top'.
  subroutine side_groups(mesh)
    type(mesh_t), intent(inout) :: mesh
    integer :: side, k, ne
    integer, allocatable :: nodes(:)
    character(len=6), parameter :: names(4) = ['left  ', 'right ', 'bottom', 'top   ']

    mesh%ngroup = 4
    allocate (mesh%group(4))
    mesh%file_groups = 'left right bottom top'
    do side = 1, 4
      call side_nodes(mesh, side, nodes)
      ne = size(nodes) - 1
      mesh%group(side)%name = trim(names(side))
      mesh%group(side)%nedge = ne
      allocate (mesh%group(side)%edge(2, ne), mesh%group(side)%cell(ne))
      do k = 1, ne
        ! counter-clockwise around the body: bottom and right along increasing s, top and
        ! left against it
        if (side == SIDE_BOTTOM .or. side == SIDE_RIGHT) then
          mesh%group(side)%edge(:, k) = [nodes(k), nodes(k + 1)]
        else
          mesh%group(side)%edge(:, k) = [nodes(k + 1), nodes(k)]
        end if
        mesh%group(side)%cell(k) = side_cell(mesh, side, k)
      end do
    end do
  end subroutine side_groups

  !> The cell bounded by edge k (1-based along increasing s) of a side of a structured mesh.
  pure integer function side_cell(mesh, side, k) result(c)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: side, k
    integer :: i, j, q
    select case (side)
    case (SIDE_LEFT)
      i = 0; j = k - 1
    case (SIDE_RIGHT)
      i = mesh%nx - 1; j = k - 1
    case (SIDE_BOTTOM)
      i = k - 1; j = 0
    case default
      i = k - 1; j = mesh%ny - 1
    end select
    q = 1 + i + j*mesh%nx
    if (mesh%element == ELEM_Q1) then
      c = q
    else if (side == SIDE_BOTTOM .or. side == SIDE_RIGHT) then
      c = 2*q - 1    ! below the diagonal
    else
      c = 2*q        ! above the diagonal
    end if
  end function side_cell

  !> The index of the group called `name` (case-sensitive, as Gmsh writes it), 0 if none.
  pure integer function group_index(mesh, name) result(g)
    type(mesh_t), intent(in) :: mesh
    character(len=*), intent(in) :: name
    do g = 1, mesh%ngroup
      if (mesh%group(g)%name == trim(name)) return
    end do
    g = 0
  end function group_index

  !> The names of the body's groups, quoted and comma-separated, a physical point's
  !! followed by ' (point)', a curve's inside the body by ' (inside the body)' (a volume
  !! mesh's other groups of nodes only, a physical curve or a surface inside the body, by
  !! ' (nodes only)') (for messages). A subroutine, not a function: messages are built on
  !! threads (doc/developing.md, Conventions).
  subroutine group_names(mesh, s)
    type(mesh_t), intent(in) :: mesh
    character(len=:), allocatable, intent(out) :: s
    integer :: g
    s = ''
    do g = 1, mesh%ngroup
      if (g > 1) s = s//', '
      s = s//"'"//mesh%group(g)%name//"'"
      if (mesh%group(g)%point) then
        s = s//' (point)'
      else if (nodes_only(mesh, g) .and. size(mesh%xy, 1) == 3) then
        s = s//' (nodes only)'        ! a physical curve, or a surface inside the body
      else if (nodes_only(mesh, g)) then
        s = s//' (inside the body)'
      end if
    end do
    if (mesh%ngroup == 0) s = '(none)'
  end subroutine group_names

  !> The distinct nodes of group g (those of its edges and its single nodes), in
  !! increasing node id.
  subroutine group_nodes(mesh, g, nodes)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: g
    integer, allocatable, intent(out) :: nodes(:)
    logical, allocatable :: on(:)
    integer :: k
    allocate (on(mesh%nnode))
    on = .false.
    do k = 1, mesh%group(g)%nedge
      on(pack(mesh%group(g)%edge(:, k), mesh%group(g)%edge(:, k) > 0)) = .true.
    end do
    do k = 1, mesh%group(g)%nnode
      on(mesh%group(g)%node(k)) = .true.
    end do
    nodes = pack([(k, k=1, mesh%nnode)], on)
  end subroutine group_nodes

  !> Whether group g has nodes but no boundary edge (a physical point, or a physical curve
  !! inside the body): it can carry prescribed displacements, but no traction and no contact.
  pure logical function nodes_only(mesh, g)
    type(mesh_t), intent(in) :: mesh   !< the body's mesh
    integer, intent(in) :: g           !< a group index (group_index), 1..ngroup
    nodes_only = mesh%group(g)%nedge == 0 .and. mesh%group(g)%nnode > 0
  end function nodes_only

  !> The sentence refusing group g (nodes_only) where boundary edges are needed: `use` is
  !! what needs them, with its verb, e.g. 'a traction needs' or 'contact needs'. In space
  !! (a volume mesh) what is needed is a surface with faces on the boundary.
  subroutine nodes_only_refusal(mesh, g, use, s)
    type(mesh_t), intent(in) :: mesh        !< the body's mesh
    integer, intent(in) :: g                !< a group without edges (nodes_only)
    character(len=*), intent(in) :: use     !< what needs a curve, with its verb
    character(len=:), allocatable, intent(out) :: s   !< the sentence
    if (size(mesh%xy, 1) == 3) then
      if (mesh%group(g)%point) then
        s = "group '"//mesh%group(g)%name//"' is a physical point: "//use//' a surface'
      else
        s = "group '"//mesh%group(g)%name//"' has no face on the boundary of the body (a physical curve, or a "// &
            'surface inside the body): '//use//' a surface on the boundary'
      end if
      s = s//' (a physical surface with faces on the boundary of the body); a group of nodes can '// &
          'only prescribe displacements (&boundary)'
      return
    end if
    if (mesh%group(g)%point) then
      s = "group '"//mesh%group(g)%name//"' is a physical point: "//use//' a curve'
    else
      s = "group '"//mesh%group(g)%name//"' is a curve inside the body, with no edge on its "// &
          'boundary: '//use//' a curve on the boundary'
    end if
    s = s//' (a physical curve with edges on the boundary of the body); a group of nodes can '// &
        'only prescribe displacements (&boundary)'
  end subroutine nodes_only_refusal

  !> The nodes on one side of the mesh, ordered by increasing s (x on bottom/top,
  !! y on left/right), corners included. An unknown side gives an empty list.
  subroutine side_nodes(mesh, side, nodes)
    type(mesh_t), intent(in) :: mesh                 !< the mesh
    integer, intent(in) :: side                      !< SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM or SIDE_TOP
    integer, allocatable, intent(out) :: nodes(:)    !< node ids along the side
    integer :: k

    if (mesh%box) then       ! a box's side: its group's nodes, in increasing id
      call group_nodes(mesh, side, nodes)
      return
    end if
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
