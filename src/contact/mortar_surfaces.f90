!> Dual mortar coupling of a non-matching or curved two-body contact interface in 3D, the
!! surface implementation of module mortar's contract (`mortar_t`, module mortar_rows)
!! (METHOD-3D.md sections 2.1-2.5). Pure geometry: from the slave and master contact faces
!! it builds, per slave node that carries a multiplier, the weighted normal gap constraint
!!
!!     sum_k ws_k n_j.u^s_k - sum_l wm_l n_j.u^m_l <= g0_j,
!!     ws_k = int Phi_j N_k dA / D_jj,  wm_l = M_jl / D_jj = int Phi_j (N^m_l o pi) dA / D_jj,
!!
!! with D_jj = int N_j dA (tributary area), N_k the slave shape functions, Phi_j their dual
!! functions and pi the projection onto the master surface. Rules as implemented:
!!
!! - Faces. A face is 4 node ids (a bilinear quadrilateral) or 3 and a 0 (a linear
!!   triangle), counter-clockwise seen from outside its body; the lists may mix both. A node
!!   id out of range, a repeated node, a face of zero area or a quadrilateral that is not
!!   convex is bad input (named by side, face position and node tags).
!! - Nodal normals. n_j = normalise(sum_f n_f(x_j)) over the slave faces f at node j, with
!!   n_f(x_j) the unit normal of f at the node (a triangle's own normal; a quadrilateral's
!!   from its two edges at that corner, the bilinear tangents there).
!! - Dual basis. Triangles Phi_i = 3 l_i - l_j - l_k (exact integers); quadrilaterals
!!   Phi = A_e N, A_e = D_e M_e^-1, M_e = int_e N N' dA and D_e its row sums (3x3 Gauss on
!!   the surface Jacobian, so warped faces too). A slave face with kept nodes K_e and nodes
!!   without a row B_e (removable, or not covered by the master) uses METHOD-3D 2.4's
!!   modified functions Nhat_k = N_k + sum_b c_kb N_b (c_kb shared equally among the kept
!!   nodes that share an edge with b, all kept nodes of the face if none does), Phi_hat =
!!   Ahat Nhat, Ahat = Dhat Mhat^-1: on every face with a kept node the kept duals sum to 1.
!! - Pairing. Master faces are bucketed on a uniform grid of about their mean size (no more
!!   than 4 cells per master face); a slave face is paired with the master faces whose
!!   bounding box meets its own extruded by +-d along its centre normal n_0, d twice the
!!   larger of its longest edge and the mean master longest edge (a master farther than
!!   about d along the normal is not seen), whose projections can overlap, and that face it
!!   (n_m.n_0 < -1e-3, n_m the master face's centre normal): O(nf_s + nf_m) for two
!!   surfaces of similar size.
!! - Integration (segment-based). Per pair: the auxiliary plane through the slave face's
!!   centre x_0 normal to n_0; both faces projected onto it; the master polygon clipped to the
!!   slave one (Sutherland-Hodgman, tolerance 1e-12 of the slave face size); a clip polygon
!!   below 1e-12 of the slave face's projected area dropped; the rest cut into a fan of
!!   triangles from its vertex mean and integrated by the 7-point degree-5 rule. At each
!!   point y the slave coordinates invert the face's projected map (closed form on
!!   triangles, Newton on quadrilaterals), the master coordinates those of the master point
!!   that projects onto y along n_0, and the weight is scaled by the slave face's surface
!!   over plane Jacobian (1 on a planar face). What is stored per pair is the standard mixed
!!   matrix int N_a (N^m_l o pi) dA, per slave face the covered mass int_cov N_a N_b dA: the
!!   dual coefficients apply afterwards, so the rows are rebuilt cheaply when they change.
!!   Triangles and parallelograms on a flat interface are integrated exactly; trapezoids
!!   and warped faces to quadrature accuracy (mortar_consistency measures it).
!! - Coverage and removed nodes. A slave node is covered when it lies (within 1e-10 of its
!!   face's size) inside the projection of a facing master face on one of its faces' planes.
!!   A node carries a row when it is covered and not `removable`. A face whose clip
!!   polygons sum to its projected area (to 1e-12) is covered whole.
!! - Rows. The slave entries of row j, own node first: on a face covered whole with
!!   unmodified functions exactly D_e(j) for the own node (so a row whose faces are all such
!!   has the single weight 1); on a covered face with modified functions int Phi_hat_j N_a
!!   over the face (its mass matrix) for each of its nodes: the removed nodes' share and,
!!   unlike 2D, the face's other kept nodes (Phi_hat_j is biorthogonal to their Nhat, not
!!   to their N); weights below 1e-14, an exact zero's rounding, are left out. On a partly
!!   covered face both sides over the covered part only, with the same points. So
!!   sum ws = sum wm on every row: to rounding where the rule is exact (triangles and
!!   parallelograms on a flat interface), to quadrature accuracy on trapezoids and warped
!!   faces. D_jj = int N_j over the whole support. A row whose master weights sum below
!!   1e-3 is dropped as not covered (its neighbours' functions are modified, the rows
!!   rebuilt).
!! - g0_j = sum_l wm_l n_j.(x^m_l - x^s_j) - sum_k ws_k n_j.(x^s_k - x^s_j), the row at
!!   u = 0 written relative to x^s_j: a uniform gap h gives h times the row's weight sum.
!! - Rows are in increasing slave node id; s = 0 (no arc length in 3D).
!! - Limitation: a partly covered slave face none of whose nodes is covered (a master corner
!!   poking into it) has no kept node; the master area over it gets no multiplier.
module mortar_surfaces
  use kinds, only: wp
  use strings, only: i2s
  use errors, only: error_t, ERR_INPUT
  use mortar_rows, only: mortar_t
  implicit none (type, external)
  private

  public :: surface_mortar

  integer, parameter :: NQ = 7                     ! points of the triangle rule (degree 5)
  real(wp), parameter :: S15 = sqrt(15.0_wp)
  real(wp), parameter :: QA1 = (6.0_wp - S15) / 21.0_wp, QB1 = 1.0_wp - 2.0_wp * QA1
  real(wp), parameter :: QA2 = (6.0_wp + S15) / 21.0_wp, QB2 = 1.0_wp - 2.0_wp * QA2
  real(wp), parameter :: QW1 = (155.0_wp - S15) / 1200.0_wp, QW2 = (155.0_wp + S15) / 1200.0_wp
  ! barycentric coordinates of the points (centroid, then two orbits of three), weights per unit area
  real(wp), parameter :: QL(3, NQ) = reshape([1.0_wp / 3.0_wp, 1.0_wp / 3.0_wp, 1.0_wp / 3.0_wp, &
                                              QB1, QA1, QA1, QA1, QB1, QA1, QA1, QA1, QB1, &
                                              QB2, QA2, QA2, QA2, QB2, QA2, QA2, QA2, QB2], [3, NQ])
  real(wp), parameter :: QW(NQ) = [9.0_wp / 40.0_wp, QW1, QW1, QW1, QW2, QW2, QW2]
  ! 3-point Gauss on [-1, 1] (the quadrilateral mass matrices, 3x3)
  real(wp), parameter :: G3(3) = [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)]
  real(wp), parameter :: W3(3) = [5.0_wp / 9.0_wp, 8.0_wp / 9.0_wp, 5.0_wp / 9.0_wp]
  ! reference corners of the quadrilateral, counter-clockwise
  real(wp), parameter :: XA(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]
  real(wp), parameter :: EA(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]

  real(wp), parameter :: TOL_CLIP = 1.0e-12_wp     ! clipping tolerance, relative to the slave face size
  real(wp), parameter :: TOL_COVER = 1.0e-10_wp    ! a node this close (relative) to a master face is covered
  real(wp), parameter :: TOL_FULL = 1.0e-12_wp     ! relative shortfall of a face's area still counted as covered
  real(wp), parameter :: MIN_AREA = 1.0e-12_wp     ! clip polygons below this fraction of the slave face are dropped
  real(wp), parameter :: TOL_GEOM = 1.0e-12_wp     ! a face's area or corner below this times its size^2 is degenerate
  real(wp), parameter :: MIN_FACING = 1.0e-3_wp    ! cosine between n_0 and -n_m below which a pair is dropped
  real(wp), parameter :: MIN_WEIGHT = 1.0e-3_wp    ! a row whose master weights sum below this is dropped
  real(wp), parameter :: TOL_ZERO = 1.0e-14_wp     ! another node's slave weight this small is an exact zero's rounding
  real(wp), parameter :: SEARCH = 2.0_wp           ! search distance in face sizes

  !> One side's faces and the geometry every step needs.
  type :: face_set_t
    integer :: n = 0                                ! faces
    integer, allocatable :: nv(:)                   ! (n) vertices: 3 or 4
    integer, allocatable :: nod(:, :)               ! (4, n) node ids (row 4 = 0 on a triangle)
    real(wp), allocatable :: x0(:, :)               ! (3, n) centre (xi = eta = 0; the centroid of a triangle)
    real(wp), allocatable :: n0(:, :)               ! (3, n) unit normal at the centre
    real(wp), allocatable :: h(:)                   ! (n) longest edge
    real(wp), allocatable :: rad(:)                 ! (n) farthest vertex from the centre
    real(wp), allocatable :: lo(:, :), hi(:, :)     ! (3, n) bounding box
  end type face_set_t

  !> Master faces bucketed on a uniform grid (cells in x fastest).
  type :: grid_t
    real(wp) :: lo(3) = 0.0_wp                      ! lower corner
    real(wp) :: c = 1.0_wp                          ! cell size
    integer :: n(3) = 1                             ! cells per direction
    integer, allocatable :: ptr(:), item(:)         ! master faces of each cell (CSR)
  end type grid_t

  !> The work of one surface_mortar: both sides' faces, the slave planes and mass matrices,
  !! the integrated pairs, coverage, and the dual coefficients of the current rows.
  type :: surface_work_t
    type(face_set_t) :: sf, mf                      ! slave and master faces
    real(wp), allocatable :: e1(:, :), e2(:, :)     ! (3, nf_s) in-plane unit basis of each slave face's plane
    real(wp), allocatable :: pv(:, :, :)            ! (2, 4, nf_s) projected slave vertices (counter-clockwise)
    real(wp), allocatable :: pc(:, :, :)            ! (2, 4, nf_s) coefficients of the projected map
    real(wp), allocatable :: tb(:, :, :)            ! (3, 3, nf_s) quadrilateral tangent coefficients b1, b2, b3
    logical, allocatable :: warped(:)               ! (nf_s) a quadrilateral out of its plane (the area ratio is not 1)
    real(wp), allocatable :: parea(:)               ! (nf_s) projected area
    real(wp), allocatable :: me(:, :, :)            ! (4, 4, nf_s) mass matrix int N_a N_b dA
    real(wp), allocatable :: de(:, :)               ! (4, nf_s) int N_a dA
    real(wp), allocatable :: sc(:, :, :)            ! (4, 4, nf_s) covered mass int_cov N_a N_b dA
    real(wp), allocatable :: cov(:)                 ! (nf_s) covered projected area
    logical, allocatable :: full(:)                 ! (nf_s) covered whole
    integer :: np = 0, nrej = 0                     ! pairs kept, pairs dropped as not facing
    integer, allocatable :: pptr(:), pm(:)          ! pairs grouped by slave face (CSR), their master face
    real(wp), allocatable :: pmt(:, :, :)           ! (4, 4, np) int N_a (N^m_l o pi) dA
    integer, allocatable :: fptr(:), flist(:), floc(:)  ! slave node -> faces, and its place in each
    real(wp), allocatable :: nn(:, :)               ! (3, nnode_s) nodal unit normals
    real(wp), allocatable :: dn(:)                  ! (nnode_s) D_jj
    logical, allocatable :: covered(:), isrow(:)    ! (nnode_s) node covered, node carries a row
    integer, allocatable :: kind(:)                 ! (nf_s) 0: no kept node, 1: plain duals, 2: modified
    real(wp), allocatable :: pd(:, :, :)            ! (4, 4, nf_s) dual coefficients, Phi_a = sum_c pd(a, c) N_c
  end type surface_work_t

contains

  !> Build the dual mortar rows of a slave contact surface against a master surface (3D).
  !! err (ERR_INPUT, naming the side and the face or node) on bad input, or when no slave
  !! node ends up with a row (no overlap, master faces facing away, all removable).
  subroutine surface_mortar(xs, fs, removable, xm, fm, mt, err, tag_s, tag_m)
    real(wp), intent(in) :: xs(:, :)        !< (3, nnode_s) slave body node coordinates [length]
    integer, intent(in) :: fs(:, :)         !< (4, nf_s) slave contact faces (node ids; row 4 = 0: a triangle), counter-clockwise seen from outside
    logical, intent(in) :: removable(:)     !< (nnode_s) the slave node may carry no multiplier (normal displacement prescribed on both bodies)
    real(wp), intent(in) :: xm(:, :)        !< (3, nnode_m) master body node coordinates [length]
    integer, intent(in) :: fm(:, :)         !< (4, nf_m) master contact faces, counter-clockwise seen from outside the master
    type(mortar_t), intent(out) :: mt       !< the constraint rows
    type(error_t), intent(out) :: err       !< the bad input, if any
    integer, intent(in), optional :: tag_s(:), tag_m(:)   !< (nnode_s), (nnode_m) node tags for messages
    type(surface_work_t) :: w
    type(grid_t) :: grid
    integer :: iter, nbad, nns

    if (size(xs, 1) /= 3 .or. size(xm, 1) /= 3 .or. size(fs, 1) /= 4 .or. size(fm, 1) /= 4) then
      call err%set(ERR_INPUT, 'mortar: surface node coordinates must be (3, nnode) arrays and faces (4, nface)')
      return
    end if
    nns = size(xs, 2)
    if (size(removable) /= nns) then
      call err%set(ERR_INPUT, 'mortar: removable has '//i2s(size(removable))//' entries for '//i2s(nns)//' slave nodes')
      return
    end if
    if (size(fs, 2) == 0) then
      call err%set(ERR_INPUT, 'mortar: no slave faces (the slave contact surface is empty)')
      return
    end if
    if (size(fm, 2) == 0) then
      call err%set(ERR_INPUT, 'mortar: no master faces (the master contact surface is empty)')
      return
    end if
    call face_geometry(xs, fs, 'slave', w%sf, err, tag_s)
    if (err%failed()) return
    call face_geometry(xm, fm, 'master', w%mf, err, tag_m)
    if (err%failed()) return

    call node_faces(w, nns)
    call slave_normals(w, xs, err, tag_s)
    if (err%failed()) return
    call slave_planes(w, xs)
    call build_grid(w%mf, grid)
    call pair_faces(w, xm, grid)

    allocate (w%isrow(nns))
    w%isrow = w%covered .and. .not. removable
    do iter = 1, nns + 2
      call face_duals(w)
      call build_rows(w, xs, xm, mt, nbad)
      if (nbad == 0) exit
    end do

    if (mt%m == 0) then
      if (w%np == 0 .and. w%nrej > 0) then
        call err%set(ERR_INPUT, 'mortar: every master face over the slave faces away from it (n_s.n_m >= 0): '// &
                     'both bodies'' faces must be counter-clockwise seen from outside; is one face list reversed?')
      else if (w%np == 0) then
        call err%set(ERR_INPUT, 'mortar: the master surface does not overlap the slave surface along the slave normals')
      else
        call err%set(ERR_INPUT, 'mortar: no slave node carries a multiplier (every covered slave node is removable)')
      end if
    end if
  end subroutine surface_mortar

  !> "nodes 701 702 703" (tags where given) of face k of a face list, for messages.
  function face_text(f, k, tag) result(s)
    integer, intent(in) :: f(:, :)                  !< (4, nface) the faces
    integer, intent(in) :: k                        !< the face
    integer, intent(in), optional :: tag(:)         !< node tags
    character(len=:), allocatable :: s
    integer :: a
    s = 'face '//i2s(k)//' (nodes'
    do a = 1, 4
      if (f(a, k) == 0 .and. a == 4) exit
      s = s//' '//node_name(f(a, k), tag)
    end do
    s = s//')'
  end function face_text

  !> A node's name in messages: its tag where tags are given and the id is in range.
  function node_name(id, tag) result(s)
    integer, intent(in) :: id                       !< node id
    integer, intent(in), optional :: tag(:)         !< node tags
    character(len=:), allocatable :: s
    s = i2s(id)
    if (present(tag)) then
      if (id >= 1 .and. id <= size(tag)) s = i2s(tag(id))
    end if
  end function node_name

  !> The faces of one side checked and measured: ids in range and distinct, nonzero area,
  !! quadrilaterals convex; centre, centre normal, size, radius and bounding box.
  subroutine face_geometry(x, f, side, fc, err, tag)
    real(wp), intent(in) :: x(:, :)                 !< (3, nnode) node coordinates [length]
    integer, intent(in) :: f(:, :)                  !< (4, nface) faces
    character(len=*), intent(in) :: side            !< 'slave' or 'master', for messages
    type(face_set_t), intent(out) :: fc             !< the faces and their geometry
    type(error_t), intent(inout) :: err             !< bad input
    integer, intent(in), optional :: tag(:)         !< node tags for messages
    integer :: k, a, b, nv, nn
    real(wp) :: xe(3, 4), v(3), t1(3), t2(3), area, hh, cn
    nn = size(x, 2)
    fc%n = size(f, 2)
    allocate (fc%nv(fc%n), fc%nod(4, fc%n), fc%x0(3, fc%n), fc%n0(3, fc%n), fc%h(fc%n), fc%rad(fc%n), &
              fc%lo(3, fc%n), fc%hi(3, fc%n))
    fc%nod = f
    do k = 1, fc%n
      nv = merge(3, 4, f(4, k) == 0)
      fc%nv(k) = nv
      do a = 1, nv
        if (f(a, k) < 1 .or. f(a, k) > nn) then
          call err%set(ERR_INPUT, 'mortar: '//side//' face '//i2s(k)//' has node '//i2s(f(a, k))// &
                       ' outside 1..'//i2s(nn))
          return
        end if
      end do
      do a = 1, nv
        do b = a + 1, nv
          if (f(a, k) == f(b, k)) then
            call err%set(ERR_INPUT, 'mortar: '//side//' '//face_text(f, k, tag)//' is degenerate: it repeats node '// &
                         node_name(f(a, k), tag))
            return
          end if
        end do
      end do
      xe(:, 1:nv) = x(:, f(1:nv, k))
      hh = 0.0_wp
      do a = 1, nv
        hh = max(hh, norm2(xe(:, modulo(a, nv) + 1) - xe(:, a)))
      end do
      if (nv == 3) then
        v = cross3(xe(:, 2) - xe(:, 1), xe(:, 3) - xe(:, 1))
        area = 0.5_wp * norm2(v)
      else
        t1 = 0.25_wp * (-xe(:, 1) + xe(:, 2) + xe(:, 3) - xe(:, 4))
        t2 = 0.25_wp * (-xe(:, 1) - xe(:, 2) + xe(:, 3) + xe(:, 4))
        v = cross3(t1, t2)
        area = 4.0_wp * norm2(v)
      end if
      if (.not. (area > TOL_GEOM * hh**2)) then
        call err%set(ERR_INPUT, 'mortar: '//side//' '//face_text(f, k, tag)//' is degenerate: it has zero area')
        return
      end if
      fc%n0(:, k) = v / norm2(v)
      if (nv == 4) then
        do a = 1, 4
          cn = dot_product(cross3(xe(:, modulo(a, 4) + 1) - xe(:, a), xe(:, modulo(a + 2, 4) + 1) - xe(:, a)), fc%n0(:, k))
          if (.not. (cn > TOL_GEOM * hh**2)) then
            call err%set(ERR_INPUT, 'mortar: '//side//' '//face_text(f, k, tag)//' is not convex at node '// &
                         node_name(f(a, k), tag))
            return
          end if
        end do
      end if
      fc%x0(:, k) = sum(xe(:, 1:nv), dim=2) / real(nv, wp)
      fc%h(k) = hh
      fc%rad(k) = 0.0_wp
      do a = 1, nv
        fc%rad(k) = max(fc%rad(k), norm2(xe(:, a) - fc%x0(:, k)))
      end do
      fc%lo(:, k) = minval(xe(:, 1:nv), dim=2)
      fc%hi(:, k) = maxval(xe(:, 1:nv), dim=2)
    end do
  end subroutine face_geometry

  !> The slave faces at each slave node, and the node's place (1..4) in each (CSR).
  subroutine node_faces(w, nns)
    type(surface_work_t), intent(inout) :: w        !< fptr, flist, floc set
    integer, intent(in) :: nns                      !< slave nodes
    integer :: k, a, i
    integer, allocatable :: fill(:)
    allocate (w%fptr(nns + 1))
    w%fptr = 0
    do k = 1, w%sf%n
      do a = 1, w%sf%nv(k)
        w%fptr(w%sf%nod(a, k) + 1) = w%fptr(w%sf%nod(a, k) + 1) + 1
      end do
    end do
    w%fptr(1) = 1
    do i = 1, nns
      w%fptr(i + 1) = w%fptr(i + 1) + w%fptr(i)
    end do
    allocate (w%flist(w%fptr(nns + 1) - 1), w%floc(w%fptr(nns + 1) - 1), fill(nns))
    fill = w%fptr(1:nns)
    do k = 1, w%sf%n
      do a = 1, w%sf%nv(k)
        i = w%sf%nod(a, k)
        w%flist(fill(i)) = k
        w%floc(fill(i)) = a
        fill(i) = fill(i) + 1
      end do
    end do
  end subroutine node_faces

  !> Averaged nodal normals of the slave surface (unit face normals at the node, summed);
  !! err (ERR_INPUT) where they cancel (the surface folds back on itself).
  subroutine slave_normals(w, xs, err, tag)
    type(surface_work_t), intent(inout) :: w        !< nn set
    real(wp), intent(in) :: xs(:, :)                !< (3, nnode_s) slave node coordinates [length]
    type(error_t), intent(inout) :: err             !< the fold, if any
    integer, intent(in), optional :: tag(:)         !< node tags for messages
    integer :: k, a, nv, i, cnt
    real(wp) :: v(3), s
    allocate (w%nn(3, size(xs, 2)))
    w%nn = 0.0_wp
    do k = 1, w%sf%n
      nv = w%sf%nv(k)
      do a = 1, nv
        i = w%sf%nod(a, k)
        if (nv == 3) then
          v = w%sf%n0(:, k)
        else
          v = cross3(xs(:, w%sf%nod(modulo(a, 4) + 1, k)) - xs(:, i), xs(:, w%sf%nod(modulo(a + 2, 4) + 1, k)) - xs(:, i))
          v = v / norm2(v)
        end if
        w%nn(:, i) = w%nn(:, i) + v
      end do
    end do
    do i = 1, size(xs, 2)
      cnt = w%fptr(i + 1) - w%fptr(i)
      if (cnt == 0) cycle
      s = norm2(w%nn(:, i))
      if (.not. (s > 1.0e-8_wp * real(cnt, wp))) then
        call err%set(ERR_INPUT, 'mortar: the slave surface folds back on itself at node '//node_name(i, tag)// &
                     ' (its faces'' normals cancel)')
        return
      end if
      w%nn(:, i) = w%nn(:, i) / s
    end do
  end subroutine slave_normals

  !> Per slave face: the auxiliary plane's basis, the projected vertices and map, the
  !! quadrilateral tangent coefficients, the mass matrix and D_e; the nodes' D_jj.
  subroutine slave_planes(w, xs)
    type(surface_work_t), intent(inout) :: w        !< plane data, me, de, dn set; sc, cov zeroed
    real(wp), intent(in) :: xs(:, :)                !< (3, nnode_s) slave node coordinates [length]
    integer :: k, a, nv, gi, gj, nfs
    real(wp) :: xe(3, 4), t(3), area, nf(4), jac, wt
    nfs = w%sf%n
    allocate (w%e1(3, nfs), w%e2(3, nfs), w%pv(2, 4, nfs), w%pc(2, 4, nfs), w%tb(3, 3, nfs), w%parea(nfs), &
              w%me(4, 4, nfs), w%de(4, nfs), w%sc(4, 4, nfs), w%cov(nfs), w%full(nfs), w%dn(size(xs, 2)), &
              w%warped(nfs))
    w%pv = 0.0_wp; w%pc = 0.0_wp; w%tb = 0.0_wp; w%me = 0.0_wp; w%de = 0.0_wp; w%sc = 0.0_wp; w%cov = 0.0_wp
    w%dn = 0.0_wp
    w%warped = .false.
    do k = 1, nfs
      nv = w%sf%nv(k)
      xe(:, 1:nv) = xs(:, w%sf%nod(1:nv, k))
      associate (n0 => w%sf%n0(:, k), x0 => w%sf%x0(:, k))
        t = xe(:, 2) - xe(:, 1)
        t = t - dot_product(t, n0) * n0
        w%e1(:, k) = t / norm2(t)
        w%e2(:, k) = cross3(n0, w%e1(:, k))
        do a = 1, nv
          w%pv(:, a, k) = [dot_product(w%e1(:, k), xe(:, a) - x0), dot_product(w%e2(:, k), xe(:, a) - x0)]
        end do
      end associate
      call map_coefficients(w%pv(:, :, k), nv, w%pc(:, :, k))
      w%parea(k) = polygon_area(w%pv(:, :, k), nv)
      if (nv == 3) then
        area = 0.5_wp * norm2(cross3(xe(:, 2) - xe(:, 1), xe(:, 3) - xe(:, 1)))
        w%me(1:3, 1:3, k) = area / 12.0_wp
        do a = 1, 3
          w%me(a, a, k) = area / 6.0_wp
        end do
        w%de(1:3, k) = area / 3.0_wp
      else
        w%tb(:, 1, k) = 0.25_wp * (-xe(:, 1) + xe(:, 2) + xe(:, 3) - xe(:, 4))
        w%tb(:, 2, k) = 0.25_wp * (-xe(:, 1) - xe(:, 2) + xe(:, 3) + xe(:, 4))
        w%tb(:, 3, k) = 0.25_wp * (xe(:, 1) - xe(:, 2) + xe(:, 3) - xe(:, 4))
        ! planar when b3 lies in the plane of b1, b2 (the centre normal's)
        w%warped(k) = abs(dot_product(w%tb(:, 3, k), w%sf%n0(:, k))) > 1.0e-14_wp * w%sf%h(k)
        do gi = 1, 3
          do gj = 1, 3
            nf = shape_fn(4, [G3(gi), G3(gj)])
            jac = norm2(cross3(w%tb(:, 1, k) + G3(gj) * w%tb(:, 3, k), w%tb(:, 2, k) + G3(gi) * w%tb(:, 3, k)))
            wt = W3(gi) * W3(gj) * jac
            do a = 1, 4
              w%me(1:4, a, k) = w%me(1:4, a, k) + wt * nf(a) * nf(1:4)
            end do
          end do
        end do
        w%de(1:4, k) = sum(w%me(1:4, 1:4, k), dim=2)
      end if
      do a = 1, nv
        w%dn(w%sf%nod(a, k)) = w%dn(w%sf%nod(a, k)) + w%de(a, k)
      end do
    end do
  end subroutine slave_planes

  !> Bucket the master faces on a uniform grid of about their mean size, by bounding box
  !! (no more than 4 nf_m + 64 cells: the cell is widened if needed).
  subroutine build_grid(mf, g)
    type(face_set_t), intent(in) :: mf              !< master faces
    type(grid_t), intent(out) :: g                  !< the grid
    integer :: k, i1, i2, i3, lo(3), hi(3), c
    integer, allocatable :: fill(:)
    real(wp) :: ghi(3), ncell
    g%lo = minval(mf%lo, dim=2)
    ghi = maxval(mf%hi, dim=2)
    g%c = 0.0_wp
    do k = 1, mf%n
      g%c = g%c + maxval(mf%hi(:, k) - mf%lo(:, k))
    end do
    g%c = g%c / real(mf%n, wp)
    do
      ncell = product(real(floor((ghi - g%lo) / g%c), wp) + 1.0_wp)
      if (ncell <= 4.0_wp * real(mf%n, wp) + 64.0_wp) exit
      g%c = g%c * 1.25_wp
    end do
    g%n = floor((ghi - g%lo) / g%c) + 1
    allocate (g%ptr(product(g%n) + 1))
    g%ptr = 0
    do k = 1, mf%n
      call cell_range(g, mf%lo(:, k), mf%hi(:, k), lo, hi)
      do i3 = lo(3), hi(3)
        do i2 = lo(2), hi(2)
          do i1 = lo(1), hi(1)
            c = cell_id(g, i1, i2, i3)
            g%ptr(c + 1) = g%ptr(c + 1) + 1
          end do
        end do
      end do
    end do
    g%ptr(1) = 1
    do c = 1, product(g%n)
      g%ptr(c + 1) = g%ptr(c + 1) + g%ptr(c)
    end do
    allocate (g%item(g%ptr(product(g%n) + 1) - 1), fill(product(g%n)))
    fill = g%ptr(1:product(g%n))
    do k = 1, mf%n
      call cell_range(g, mf%lo(:, k), mf%hi(:, k), lo, hi)
      do i3 = lo(3), hi(3)
        do i2 = lo(2), hi(2)
          do i1 = lo(1), hi(1)
            c = cell_id(g, i1, i2, i3)
            g%item(fill(c)) = k
            fill(c) = fill(c) + 1
          end do
        end do
      end do
    end do
  end subroutine build_grid

  !> The cells (0-based, clamped to the grid) a box [blo, bhi] meets; lo > hi in some
  !! direction when it misses the grid.
  pure subroutine cell_range(g, blo, bhi, lo, hi)
    type(grid_t), intent(in) :: g                   !< the grid
    real(wp), intent(in) :: blo(3), bhi(3)          !< the box [length]
    integer, intent(out) :: lo(3), hi(3)            !< first and last cell per direction
    real(wp) :: a(3), b(3)
    a = (blo - g%lo) / g%c
    b = (bhi - g%lo) / g%c
    lo = 0
    hi = -1
    if (any(b < 0.0_wp) .or. any(a >= real(g%n, wp))) return
    lo = max(0, floor(a))
    hi = min(g%n - 1, floor(b))
  end subroutine cell_range

  !> The 1-based id of cell (i1, i2, i3) (0-based indices).
  pure integer function cell_id(g, i1, i2, i3)
    type(grid_t), intent(in) :: g                   !< the grid
    integer, intent(in) :: i1, i2, i3               !< cell indices
    cell_id = 1 + i1 + g%n(1) * (i2 + g%n(2) * i3)
  end function cell_id

  !> Every slave face against the master faces the grid offers near it: the pairs that
  !! face each other and overlap are integrated (pair_integrate), grouped by slave face.
  subroutine pair_faces(w, xm, g)
    type(surface_work_t), intent(inout) :: w        !< pairs, coverage and covered mass filled
    real(wp), intent(in) :: xm(:, :)                !< (3, nnode_m) master node coordinates [length]
    type(grid_t), intent(in) :: g                   !< the master faces' grid
    integer :: s, e, i1, i2, i3, c, p, lo(3), hi(3)
    integer, allocatable :: seen(:)
    real(wp) :: hbar, margin, d(3), dn, dp, qlo(3), qhi(3)
    allocate (seen(w%mf%n), w%pptr(w%sf%n + 1), w%pm(4 * w%sf%n + 16), w%pmt(4, 4, 4 * w%sf%n + 16), &
              w%covered(size(w%nn, 2)))
    seen = 0
    w%covered = .false.
    hbar = sum(w%mf%h) / real(w%mf%n, wp)
    w%np = 0
    w%nrej = 0
    do s = 1, w%sf%n
      w%pptr(s) = w%np + 1
      ! the slave face's box extruded by +-margin along its normal, a little wider
      margin = SEARCH * max(w%sf%h(s), hbar)
      qlo = w%sf%lo(:, s) - margin * abs(w%sf%n0(:, s)) - 1.0e-9_wp * w%sf%h(s)
      qhi = w%sf%hi(:, s) + margin * abs(w%sf%n0(:, s)) + 1.0e-9_wp * w%sf%h(s)
      call cell_range(g, qlo, qhi, lo, hi)
      do i3 = lo(3), hi(3)
        do i2 = lo(2), hi(2)
          do i1 = lo(1), hi(1)
            c = cell_id(g, i1, i2, i3)
            do p = g%ptr(c), g%ptr(c + 1) - 1
              e = g%item(p)
              if (seen(e) == s) cycle
              seen(e) = s
              if (any(w%mf%hi(:, e) < qlo) .or. any(w%mf%lo(:, e) > qhi)) cycle
              ! the projections cannot overlap when the centres are farther apart in the plane
              d = w%mf%x0(:, e) - w%sf%x0(:, s)
              dn = dot_product(d, w%sf%n0(:, s))
              dp = norm2(d - dn * w%sf%n0(:, s))
              if (dp > (1.0_wp + 1.0e-9_wp) * (w%sf%rad(s) + w%mf%rad(e))) cycle
              if (.not. (dot_product(w%mf%n0(:, e), w%sf%n0(:, s)) < -MIN_FACING)) then
                w%nrej = w%nrej + 1
                cycle
              end if
              call pair_integrate(w, xm, s, e, mass_only=.false.)
            end do
          end do
        end do
      end do
    end do
    w%pptr(w%sf%n + 1) = w%np + 1
    w%full = w%cov >= (1.0_wp - TOL_FULL) * w%parea
    ! the covered mass, needed on the partly covered faces only: their pairs once more
    do s = 1, w%sf%n
      if (w%full(s)) cycle
      do p = w%pptr(s), w%pptr(s + 1) - 1
        call pair_integrate(w, xm, s, w%pm(p), mass_only=.true.)
      end do
    end do
  end subroutine pair_faces

  !> Slave face s against master face e: clip their projections on s's auxiliary plane and
  !! integrate over the clip polygon (fan of triangles from its vertex mean, 7-point rule):
  !! int N_a (N^m_l o pi), stored as a new pair, with the slave nodes the master face covers
  !! marked and the covered area added; or (mass_only) int N_a N_b added to the face's
  !! covered mass.
  subroutine pair_integrate(w, xm, s, e, mass_only)
    type(surface_work_t), intent(inout) :: w        !< the pair appended, cov and covered updated; or sc
    real(wp), intent(in) :: xm(:, :)                !< (3, nnode_m) master node coordinates [length]
    integer, intent(in) :: s, e                     !< slave face, master face
    logical, intent(in) :: mass_only                !< accumulate the covered mass only
    real(wp) :: q(2, 4), cp(2, 4), qc(2, 4), poly(2, 16), gc(2), v1(2), v2(2), y(2), xis(2), xim(2), &
                ns(4), nm(4), mt(4, 4), sc(4, 4), d(3), ar, area, ca, wt
    integer :: nvs, nvm, l, a, np, i, k
    nvs = w%sf%nv(s)
    nvm = w%mf%nv(e)
    do l = 1, nvm
      d = xm(:, w%mf%nod(l, e)) - w%sf%x0(:, s)
      q(:, l) = [dot_product(w%e1(:, s), d), dot_product(w%e2(:, s), d)]
    end do
    ar = polygon_area(q, nvm)
    if (.not. (abs(ar) > MIN_AREA * w%parea(s))) return
    if (ar > 0.0_wp) then
      cp(:, 1:nvm) = q(:, 1:nvm)
    else
      cp(:, 1:nvm) = q(:, nvm:1:-1)
    end if
    call clip_convex(w%pv(:, :, s), nvs, cp, nvm, TOL_CLIP * w%sf%h(s), poly, np)
    if (np < 3) return
    area = polygon_area(poly, np)
    if (.not. (area > MIN_AREA * w%parea(s))) return
    if (.not. mass_only) then
      do a = 1, nvs
        if (w%covered(w%sf%nod(a, s))) cycle
        if (inside_convex(cp, nvm, w%pv(:, a, s), TOL_COVER * w%sf%h(s))) w%covered(w%sf%nod(a, s)) = .true.
      end do
    end if
    call map_coefficients(q, nvm, qc)
    gc = sum(poly(:, 1:np), dim=2) / real(np, wp)
    mt = 0.0_wp
    sc = 0.0_wp
    do i = 1, np
      v1 = poly(:, i)
      v2 = poly(:, modulo(i, np) + 1)
      ca = 0.5_wp * cross2(v1 - gc, v2 - gc)
      if (.not. (ca > 0.0_wp)) cycle
      do k = 1, NQ
        y = QL(1, k) * gc + QL(2, k) * v1 + QL(3, k) * v2
        call invert_map(w%pc(:, :, s), nvs, y, xis)
        ns = shape_fn(nvs, xis)
        wt = QW(k) * ca
        if (w%warped(s)) wt = wt * surface_ratio(w%tb(:, :, s), w%sf%n0(:, s), xis)
        ns = wt * ns
        if (mass_only) then
          nm = shape_fn(nvs, xis)
          do l = 1, 4
            sc(:, l) = sc(:, l) + nm(l) * ns
          end do
        else
          call invert_map(qc, nvm, y, xim)
          nm = shape_fn(nvm, xim)
          do l = 1, 4
            mt(:, l) = mt(:, l) + nm(l) * ns
          end do
        end if
      end do
    end do
    if (mass_only) then
      w%sc(:, :, s) = w%sc(:, :, s) + sc
      return
    end if
    w%cov(s) = w%cov(s) + area
    if (w%np == size(w%pm)) call grow_pairs(w)
    w%np = w%np + 1
    w%pm(w%np) = e
    w%pmt(:, :, w%np) = mt
  end subroutine pair_integrate

  !> Double the capacity of the pair arrays.
  subroutine grow_pairs(w)
    type(surface_work_t), intent(inout) :: w        !< pm, pmt enlarged
    integer, allocatable :: ti(:)
    real(wp), allocatable :: tr(:, :, :)
    integer :: np
    np = w%np
    allocate (ti(2 * size(w%pm)))
    ti(1:np) = w%pm(1:np)
    call move_alloc(ti, w%pm)
    allocate (tr(4, 4, size(w%pm)))
    tr(:, :, 1:np) = w%pmt(:, :, 1:np)
    call move_alloc(tr, w%pmt)
  end subroutine grow_pairs

  !> The dual coefficients of every slave face for the current rows: kind 0 (no kept node),
  !! 1 (every node kept: A_e = D_e M_e^-1, triangles the integers 3, -1), 2 (modified,
  !! METHOD-3D 2.4): pd(a, :) are the coefficients of kept node a's dual function in N.
  subroutine face_duals(w)
    type(surface_work_t), intent(inout) :: w        !< kind and pd set from isrow
    integer :: k, nv, a, b, nk, i, nb, kept(4), pos(4)
    real(wp) :: c(4, 4), mh(4, 4), mi(4, 4), dh(4)
    logical :: keep(4), nbr
    if (.not. allocated(w%kind)) allocate (w%kind(w%sf%n), w%pd(4, 4, w%sf%n))
    do k = 1, w%sf%n
      nv = w%sf%nv(k)
      w%pd(:, :, k) = 0.0_wp
      nk = 0
      pos = 0
      do a = 1, nv
        keep(a) = w%isrow(w%sf%nod(a, k))
        if (keep(a)) then
          nk = nk + 1
          kept(nk) = a
          pos(a) = nk
        end if
      end do
      if (nk == 0) then
        w%kind(k) = 0
      else if (nk == nv .and. nv == 3) then
        w%kind(k) = 1
        w%pd(1:3, 1:3, k) = -1.0_wp
        do a = 1, 3
          w%pd(a, a, k) = 3.0_wp
        end do
      else
        ! C (nk x nv): Nhat = C N, the identity on the kept nodes, c_kb on the removed ones
        c = 0.0_wp
        do i = 1, nk
          c(i, kept(i)) = 1.0_wp
        end do
        do b = 1, nv
          if (keep(b)) cycle
          nb = 0
          do i = 1, nk
            if (edge_neighbours(nv, b, kept(i))) nb = nb + 1
          end do
          do i = 1, nk
            nbr = edge_neighbours(nv, b, kept(i))
            if (nb == 0) then
              c(i, b) = 1.0_wp / real(nk, wp)
            else if (nbr) then
              c(i, b) = 1.0_wp / real(nb, wp)
            end if
          end do
        end do
        w%kind(k) = merge(1, 2, nk == nv)
        mh(1:nk, 1:nk) = matmul(c(1:nk, 1:nv), matmul(w%me(1:nv, 1:nv, k), transpose(c(1:nk, 1:nv))))
        dh(1:nk) = matmul(c(1:nk, 1:nv), w%de(1:nv, k))
        call small_inverse(mh, mi, nk)
        do i = 1, nk
          mi(i, 1:nk) = dh(i) * mi(i, 1:nk)
        end do
        mh(1:nk, 1:nv) = matmul(mi(1:nk, 1:nk), c(1:nk, 1:nv))
        do i = 1, nk
          w%pd(kept(i), 1:nv, k) = mh(i, 1:nv)
        end do
      end if
    end do
  end subroutine face_duals

  !> Do local nodes a and b of an nv-node face share an edge?
  pure logical function edge_neighbours(nv, a, b)
    integer, intent(in) :: nv                       !< 3 or 4
    integer, intent(in) :: a, b                     !< local nodes
    if (nv == 3) then
      edge_neighbours = a /= b
    else
      edge_neighbours = modulo(a - b, 4) == 1 .or. modulo(b - a, 4) == 1
    end if
  end function edge_neighbours

  !> Fill mt from isrow and the face duals; rows whose master weights sum below MIN_WEIGHT
  !! are switched off (nbad of them), in which case the caller builds again.
  subroutine build_rows(w, xs, xm, mt, nbad)
    type(surface_work_t), intent(inout) :: w        !< faces, pairs, duals; isrow updated
    real(wp), intent(in) :: xs(:, :)                !< (3, nnode_s) slave node coordinates [length]
    real(wp), intent(in) :: xm(:, :)                !< (3, nnode_m) master node coordinates [length]
    type(mortar_t), intent(inout) :: mt             !< the rows
    integer, intent(out) :: nbad                    !< rows dropped in this pass
    integer :: nns, m, j, i, q, f, a, b, l, p, e, nv, nvm, ns_, nm_, s0, m0, capm, caps, nd, k
    integer, allocatable :: spos(:), mpos(:)
    real(wp) :: v(4), dj, sw, g0, nj(3), wv
    nns = size(xs, 2)
    m = count(w%isrow)
    caps = 0
    capm = 0
    do i = 1, nns
      if (.not. w%isrow(i)) cycle
      caps = caps + 1
      do q = w%fptr(i), w%fptr(i + 1) - 1
        f = w%flist(q)
        caps = caps + w%sf%nv(f)
        capm = capm + 4 * (w%pptr(f + 1) - w%pptr(f))
      end do
    end do
    mt%m = m
    if (allocated(mt%snode)) deallocate (mt%snode, mt%normal, mt%d, mt%s, mt%g0, mt%sptr, mt%snod, mt%sval, &
                                         mt%mptr, mt%mnod, mt%mval)
    allocate (mt%snode(m), mt%normal(3, m), mt%d(m), mt%s(m), mt%g0(m), mt%sptr(m + 1), mt%snod(caps), &
              mt%sval(caps), mt%mptr(m + 1), mt%mnod(capm), mt%mval(capm))
    allocate (spos(nns), mpos(size(xm, 2)))
    spos = 0
    mpos = 0
    nbad = 0
    j = 0
    ns_ = 0
    nm_ = 0
    do i = 1, nns
      if (.not. w%isrow(i)) cycle
      j = j + 1
      mt%snode(j) = i
      mt%normal(:, j) = w%nn(:, i)
      mt%s(j) = 0.0_wp
      mt%sptr(j) = ns_ + 1
      mt%mptr(j) = nm_ + 1
      s0 = ns_
      m0 = nm_
      ns_ = ns_ + 1                         ! the own node first
      mt%snod(ns_) = i
      mt%sval(ns_) = 0.0_wp
      spos(i) = ns_
      dj = w%dn(i)
      do q = w%fptr(i), w%fptr(i + 1) - 1
        f = w%flist(q)
        a = w%floc(q)
        nv = w%sf%nv(f)
        if (w%full(f) .and. w%kind(f) == 1) then
          mt%sval(s0 + 1) = mt%sval(s0 + 1) + w%de(a, f)
        else
          v = 0.0_wp
          do b = 1, nv
            if (w%full(f)) then
              v = v + w%pd(a, b, f) * w%me(b, :, f)
            else
              v = v + w%pd(a, b, f) * w%sc(b, :, f)
            end if
          end do
          do b = 1, nv
            if (v(b) == 0.0_wp) cycle
            nd = w%sf%nod(b, f)
            if (spos(nd) == 0) then
              ns_ = ns_ + 1
              spos(nd) = ns_
              mt%snod(ns_) = nd
              mt%sval(ns_) = 0.0_wp
            end if
            mt%sval(spos(nd)) = mt%sval(spos(nd)) + v(b)
          end do
        end if
        do p = w%pptr(f), w%pptr(f + 1) - 1
          e = w%pm(p)
          nvm = w%mf%nv(e)
          v = 0.0_wp
          do b = 1, nv
            v = v + w%pd(a, b, f) * w%pmt(b, :, p)
          end do
          do l = 1, nvm
            nd = w%mf%nod(l, e)
            if (mpos(nd) == 0) then
              nm_ = nm_ + 1
              mpos(nd) = nm_
              mt%mnod(nm_) = nd
              mt%mval(nm_) = 0.0_wp
            end if
            mt%mval(mpos(nd)) = mt%mval(mpos(nd)) + v(l)
          end do
        end do
      end do
      mt%d(j) = dj
      nj = w%nn(:, i)
      sw = 0.0_wp
      g0 = 0.0_wp
      do e = m0 + 1, nm_
        l = mt%mnod(e)
        mpos(l) = 0
        mt%mval(e) = mt%mval(e) / dj
        sw = sw + mt%mval(e)
        g0 = g0 + mt%mval(e) * dot_product(nj, xm(:, l) - xs(:, i))
      end do
      ! the own weight, then the other slave entries but those that are an exact zero's
      ! rounding (int Phi_hat_j N_k of two kept nodes biorthogonal on a modified face)
      spos(i) = 0
      mt%sval(s0 + 1) = mt%sval(s0 + 1) / dj
      k = s0 + 1
      do e = s0 + 2, ns_
        l = mt%snod(e)
        spos(l) = 0
        wv = mt%sval(e) / dj
        if (abs(wv) <= TOL_ZERO) cycle
        k = k + 1
        mt%snod(k) = l
        mt%sval(k) = wv
        g0 = g0 - wv * dot_product(nj, xs(:, l) - xs(:, i))
      end do
      ns_ = k
      mt%g0(j) = g0
      if (.not. (sw >= MIN_WEIGHT)) then
        nbad = nbad + 1
        w%isrow(i) = .false.
      end if
    end do
    mt%sptr(m + 1) = ns_ + 1
    mt%mptr(m + 1) = nm_ + 1
    if (nbad == 0) then
      mt%snod = mt%snod(1:ns_)
      mt%sval = mt%sval(1:ns_)
      mt%mnod = mt%mnod(1:nm_)
      mt%mval = mt%mval(1:nm_)
    end if
  end subroutine build_rows

  ! ---- plane geometry and shape functions ------------------------------------------

  !> Shape functions of the linear triangle (1 - xi - eta, xi, eta, and 0) or the bilinear
  !! quadrilateral (1 + xi xi_a)(1 + eta eta_a)/4 at reference point xi.
  pure function shape_fn(nv, xi) result(nf)
    integer, intent(in) :: nv                       !< 3 or 4 vertices
    real(wp), intent(in) :: xi(2)                   !< reference coordinates [-]
    real(wp) :: nf(4)                               !< shape function values [-] (nf(4) = 0 on a triangle)
    if (nv == 3) then
      nf = [1.0_wp - xi(1) - xi(2), xi(1), xi(2), 0.0_wp]
    else
      nf = 0.25_wp * (1.0_wp + XA * xi(1)) * (1.0_wp + EA * xi(2))
    end if
  end function shape_fn

  !> Coefficients of a face's map in the plane: triangle p1 + xi (p2 - p1) + eta (p3 - p1),
  !! quadrilateral a0 + a1 xi + a2 eta + a3 xi eta.
  pure subroutine map_coefficients(p, nv, c)
    real(wp), intent(in) :: p(:, :)                 !< (2, nv) vertices in the plane [length]
    integer, intent(in) :: nv                       !< 3 or 4
    real(wp), intent(out) :: c(2, 4)                !< the coefficients [length]
    c = 0.0_wp
    if (nv == 3) then
      c(:, 1) = p(:, 1)
      c(:, 2) = p(:, 2) - p(:, 1)
      c(:, 3) = p(:, 3) - p(:, 1)
    else
      c(:, 1) = 0.25_wp * (p(:, 1) + p(:, 2) + p(:, 3) + p(:, 4))
      c(:, 2) = 0.25_wp * (-p(:, 1) + p(:, 2) + p(:, 3) - p(:, 4))
      c(:, 3) = 0.25_wp * (-p(:, 1) - p(:, 2) + p(:, 3) + p(:, 4))
      c(:, 4) = 0.25_wp * (p(:, 1) - p(:, 2) + p(:, 3) - p(:, 4))
    end if
  end subroutine map_coefficients

  !> The reference point xi whose image under a face's plane map is y: closed form on a
  !! triangle, Newton from the affine part's inverse on a quadrilateral.
  pure subroutine invert_map(c, nv, y, xi)
    real(wp), intent(in) :: c(2, 4)                 !< map coefficients (map_coefficients) [length]
    integer, intent(in) :: nv                       !< 3 or 4
    real(wp), intent(in) :: y(2)                    !< the point in the plane [length]
    real(wp), intent(out) :: xi(2)                  !< its reference coordinates [-]
    real(wp) :: r(2), j1(2), j2(2), det, dx(2)
    integer :: it
    ! the affine part's inverse: exact on a triangle, the start of Newton on a quadrilateral
    ! (which then stops after one step on a parallelogram)
    r = y - c(:, 1)
    det = cross2(c(:, 2), c(:, 3))
    xi = [cross2(r, c(:, 3)), cross2(c(:, 2), r)] / det
    if (nv == 3 .or. all(c(:, 4) == 0.0_wp)) return
    do it = 1, 30
      r = c(:, 1) + xi(1) * c(:, 2) + xi(2) * c(:, 3) + xi(1) * xi(2) * c(:, 4) - y
      j1 = c(:, 2) + xi(2) * c(:, 4)
      j2 = c(:, 3) + xi(1) * c(:, 4)
      det = cross2(j1, j2)
      if (det == 0.0_wp) exit
      dx = [cross2(r, j2), cross2(j1, r)] / det
      xi = xi - dx
      if (maxval(abs(dx)) <= 1.0e-14_wp) exit
    end do
  end subroutine invert_map

  !> Surface over plane area element of a quadrilateral slave face at xi: |t1 x t2| /
  !! (t1 x t2).n0 (1 on a planar face).
  pure real(wp) function surface_ratio(tb, n0, xi)
    real(wp), intent(in) :: tb(3, 3)                !< tangent coefficients b1, b2, b3 [length]
    real(wp), intent(in) :: n0(3)                   !< unit normal of the auxiliary plane [-]
    real(wp), intent(in) :: xi(2)                   !< reference coordinates [-]
    real(wp) :: v(3)
    v = cross3(tb(:, 1) + xi(2) * tb(:, 3), tb(:, 2) + xi(1) * tb(:, 3))
    surface_ratio = norm2(v) / dot_product(v, n0)
  end function surface_ratio

  !> Signed area of a plane polygon (positive counter-clockwise).
  pure real(wp) function polygon_area(p, n)
    real(wp), intent(in) :: p(:, :)                 !< (2, n) vertices [length]
    integer, intent(in) :: n                        !< vertices
    integer :: i
    polygon_area = 0.0_wp
    do i = 1, n
      polygon_area = polygon_area + cross2(p(:, i), p(:, modulo(i, n) + 1))
    end do
    polygon_area = 0.5_wp * polygon_area
  end function polygon_area

  !> Is point y inside the counter-clockwise convex polygon c, within distance tol?
  pure logical function inside_convex(c, n, y, tol)
    real(wp), intent(in) :: c(:, :)                 !< (2, n) vertices [length]
    integer, intent(in) :: n                        !< vertices
    real(wp), intent(in) :: y(2)                    !< the point [length]
    real(wp), intent(in) :: tol                     !< tolerance [length]
    integer :: i
    real(wp) :: ed(2)
    inside_convex = .false.
    do i = 1, n
      ed = c(:, modulo(i, n) + 1) - c(:, i)
      if (cross2(ed, y - c(:, i)) < -tol * norm2(ed)) return
    end do
    inside_convex = .true.
  end function inside_convex

  !> Sutherland-Hodgman: the convex polygon sp clipped by the convex polygon cp (both
  !! counter-clockwise); points within tol of an edge's line count as inside; consecutive
  !! points closer than tol are merged.
  pure subroutine clip_convex(sp, ns, cp, nc, tol, op, no)
    real(wp), intent(in) :: sp(:, :)                !< (2, ns) subject polygon [length]
    integer, intent(in) :: ns                       !< its vertices
    real(wp), intent(in) :: cp(:, :)                !< (2, nc) clip polygon [length]
    integer, intent(in) :: nc                       !< its vertices
    real(wp), intent(in) :: tol                     !< tolerance [length]
    real(wp), intent(out) :: op(2, 16)              !< the intersection [length]
    integer, intent(out) :: no                      !< its vertices (< 3: none)
    real(wp) :: a(2, 16), p1(2), ed(2), len, dc, dp, t, prv(2), cur(2)
    integer :: k, i, na, m
    a(:, 1:ns) = sp(:, 1:ns)
    na = ns
    do k = 1, nc
      p1 = cp(:, k)
      ed = cp(:, modulo(k, nc) + 1) - p1
      len = norm2(ed)
      if (len == 0.0_wp) cycle
      no = 0
      do i = 1, na
        cur = a(:, i)
        prv = a(:, merge(na, i - 1, i == 1))
        dc = cross2(ed, cur - p1) / len
        dp = cross2(ed, prv - p1) / len
        if (dc >= -tol) then
          if (dp < -tol) then
            t = min(1.0_wp, max(0.0_wp, dp / (dp - dc)))
            no = no + 1
            op(:, no) = prv + t * (cur - prv)
          end if
          no = no + 1
          op(:, no) = cur
        else if (dp >= -tol) then
          t = min(1.0_wp, max(0.0_wp, dp / (dp - dc)))
          no = no + 1
          op(:, no) = prv + t * (cur - prv)
        end if
      end do
      na = no
      a(:, 1:na) = op(:, 1:na)
      if (na == 0) exit
    end do
    ! merge coincident consecutive points
    no = 0
    do i = 1, na
      if (no > 0) then
        if (norm2(a(:, i) - op(:, no)) <= tol) cycle
      end if
      no = no + 1
      op(:, no) = a(:, i)
    end do
    m = no
    do while (m > 1)
      if (norm2(op(:, m) - op(:, 1)) > tol) exit
      m = m - 1
    end do
    no = m
  end subroutine clip_convex

  !> The inverse of the leading n x n block of a small symmetric positive definite matrix
  !! (Gauss-Jordan with partial pivoting, n <= 4).
  pure subroutine small_inverse(a, ai, n)
    real(wp), intent(in) :: a(4, 4)                 !< the matrix (leading block)
    real(wp), intent(inout) :: ai(4, 4)             !< its inverse (leading block; the rest untouched)
    integer, intent(in) :: n                        !< order
    real(wp) :: t(n, 2 * n), r(2 * n)
    integer :: i, k, piv
    t = 0.0_wp
    t(:, 1:n) = a(1:n, 1:n)
    do i = 1, n
      t(i, n + i) = 1.0_wp
    end do
    do k = 1, n
      piv = k - 1 + maxloc(abs(t(k:n, k)), dim=1)
      if (piv /= k) then
        r = t(k, :); t(k, :) = t(piv, :); t(piv, :) = r
      end if
      t(k, :) = t(k, :) / t(k, k)
      do i = 1, n
        if (i /= k) t(i, :) = t(i, :) - t(i, k) * t(k, :)
      end do
    end do
    ai(1:n, 1:n) = t(:, n + 1:2 * n)
  end subroutine small_inverse

  !> Cross product in 3D.
  pure function cross3(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)              !< the vectors
    real(wp) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross3

  !> The plane cross product a(1) b(2) - a(2) b(1).
  pure real(wp) function cross2(a, b)
    real(wp), intent(in) :: a(2), b(2)              !< the vectors
    cross2 = a(1) * b(2) - a(2) * b(1)
  end function cross2

end module mortar_surfaces
