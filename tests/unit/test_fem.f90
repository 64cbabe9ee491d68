!> The manufactured solution of test_fem, in a module so that its body force can be
!! passed to assemble_body as a procedure argument (no internal-procedure trampoline).
module test_fem_manufactured
  use kinds, only: wp
  implicit none (type, external)
  private
  public :: ms_u, ms_force, ms_lame_lambda, ms_lame_mu
  real(wp), parameter :: pi = acos(-1.0_wp)
  real(wp), parameter :: ka = pi, kb = 0.5_wp*pi, kc = 0.75_wp*pi, kd_ = pi
  real(wp) :: ms_lame_lambda = 0.0_wp   !< Lame lambda of the manufactured problem
  real(wp) :: ms_lame_mu = 0.0_wp       !< shear modulus of the manufactured problem

contains

  !> Manufactured solution u = (sin(ka x) cos(kb y), cos(kc x) sin(kd y)).
  pure subroutine ms_u(x, y, u, g)
    real(wp), intent(in) :: x, y
    real(wp), intent(out) :: u(2), g(2, 2)   ! g(i,j) = d u_i / d x_j
    u(1) = sin(ka*x)*cos(kb*y)
    u(2) = cos(kc*x)*sin(kd_*y)
    g(1, 1) = ka*cos(ka*x)*cos(kb*y)
    g(1, 2) = -kb*sin(ka*x)*sin(kb*y)
    g(2, 1) = -kc*sin(kc*x)*sin(kd_*y)
    g(2, 2) = kd_*cos(kc*x)*cos(kd_*y)
  end subroutine ms_u

  !> f = -div sigma = -(lambda + mu) grad div u - mu lap u.
  subroutine ms_force(xy, f)
    real(wp), intent(in) :: xy(:)
    real(wp), intent(out) :: f(:)
    real(wp) :: x, y, u1xx, u1yy, u1xy, u2xx, u2yy, u2xy
    x = xy(1)
    y = xy(2)
    u1xx = -ka**2*sin(ka*x)*cos(kb*y)
    u1yy = -kb**2*sin(ka*x)*cos(kb*y)
    u1xy = -ka*kb*cos(ka*x)*sin(kb*y)
    u2xx = -kc**2*cos(kc*x)*sin(kd_*y)
    u2yy = -kd_**2*cos(kc*x)*sin(kd_*y)
    u2xy = -kc*kd_*sin(kc*x)*cos(kd_*y)
    f(1) = -(ms_lame_lambda + ms_lame_mu)*(u1xx + u2xy) - ms_lame_mu*(u1xx + u1yy)
    f(2) = -(ms_lame_lambda + ms_lame_mu)*(u1xy + u2yy) - ms_lame_mu*(u2xx + u2yy)
  end subroutine ms_force

end module test_fem_manufactured

!> Unit tests of modules mesh and assembly: sparse structure, patch test on a distorted
!! mesh, convergence rates against a manufactured solution, traction loads, unit scaling
!! and error reporting. Solves use LAPACK's banded Cholesky (testing's band_solve).
program test_fem
  use kinds, only: wp
  use, intrinsic :: iso_fortran_env, only: int16
  use config, only: body_cfg_t, traction_cfg_t, boundary_cfg_t, ELEM_Q1, ELEM_P1, ELEM_MIXED, element_names, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_TOP, side_names, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT
  use mesh, only: mesh_t, side_nodes
  use assembly, only: body_system_t, assemble_body, expand, residual_full, nodal_stress, csc_matvec, &
                      body_force_fn, cell_triplets
  use test_fem_manufactured, only: ms_u, ms_force, ms_lame_lambda, ms_lame_mu
  use elements, only: MAX_NVERT, MAX_NDOF, element_stiffness, q1_gradients, element_shape_integrals
  use testing, only: grid_mesh, grid_mesh_parts, report, test_summary, solve_full, error_parts
  use errors, only: error_t
  implicit none (type, external)

  real(wp), parameter :: eps = epsilon(1.0_wp)

  call test_structure(ELEM_Q1)
  call test_structure(ELEM_P1)
  call test_patch(ELEM_Q1, .true.)
  call test_patch(ELEM_Q1, .false.)
  call test_patch(ELEM_P1, .true.)
  call test_patch(ELEM_P1, .false.)
  call test_manufactured(ELEM_Q1)
  call test_manufactured(ELEM_P1)
  call test_tractions(ELEM_Q1)
  call test_tractions(ELEM_P1)
  call test_units(ELEM_Q1, .true.)
  call test_units(ELEM_P1, .false.)
  call test_errors()
  call test_triplets(ELEM_Q1, 1)
  call test_triplets(ELEM_Q1, 3)
  call test_triplets(ELEM_P1, 4)
  call test_q1_stiffness_bits()
  call test_general_scatter(ELEM_Q1)
  call test_general_scatter(ELEM_P1)
  call test_mixed_scatter()
  call test_fan_scatter()
  call test_shape_integrals()

  call test_summary()

contains

  !> The integrals of the shape functions (a constant body force's nodal loads, w(a) b) on a
  !! distorted quadrilateral and a triangle, against the polygon's area and first moments
  !! by the shoelace formulas: sum_a w(a) = area, sum_a w(a) x_a = the integral of x
  !! (isoparametric: x = sum_a N_a x_a exactly), each to rounding.
  subroutine test_shape_integrals()
    real(wp) :: xe(2, MAX_NVERT), w(MAX_NVERT), area, mx, my, cr
    integer :: n, a, b, el
    do el = 1, 2
      xe = 0.0_wp
      if (el == 1) then
        xe(:, 1:4) = reshape([0.1_wp, -0.2_wp, 2.3_wp, 0.1_wp, 1.9_wp, 1.7_wp, -0.4_wp, 1.2_wp], [2, 4])
        n = 4
        call element_shape_integrals(ELEM_Q1, xe, w)
      else
        xe(:, 1:3) = reshape([0.3_wp, 0.1_wp, 2.2_wp, 0.6_wp, 0.9_wp, 1.8_wp], [2, 3])
        n = 3
        call element_shape_integrals(ELEM_P1, xe, w)
      end if
      area = 0.0_wp
      mx = 0.0_wp
      my = 0.0_wp
      do a = 1, n
        b = mod(a, n) + 1
        cr = xe(1, a)*xe(2, b) - xe(1, b)*xe(2, a)
        area = area + 0.5_wp*cr
        mx = mx + (xe(1, a) + xe(1, b))*cr/6.0_wp
        my = my + (xe(2, a) + xe(2, b))*cr/6.0_wp
      end do
      call report(abs(sum(w(1:n)) - area) <= 8*eps*area .and. abs(sum(w(1:n)*xe(1, 1:n)) - mx) <= 8*eps*abs(mx) &
                  .and. abs(sum(w(1:n)*xe(2, 1:n)) - my) <= 8*eps*abs(my) .and. all(w(n + 1:) == 0.0_wp), &
                  merge('Q1', 'P1', el == 1)//' shape integrals: their sum is the area, their moments the polygon''s')
    end do
  end subroutine test_shape_integrals

  !> Assemble and solve one body on its mesh; stops the test on an assembly error.
  subroutine solve_body(m, body, plane_strain, tr, ntr, sys, u_full, u_prescribed, body_force)
    type(mesh_t), intent(in) :: m
    type(body_cfg_t), intent(in) :: body
    logical, intent(in) :: plane_strain
    type(traction_cfg_t), intent(in) :: tr(:)
    integer, intent(in) :: ntr
    type(body_system_t), intent(out) :: sys
    real(wp), allocatable, intent(out) :: u_full(:)
    real(wp), intent(in), optional :: u_prescribed(:)
    procedure(body_force_fn), optional :: body_force
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    call assemble_body(m, body, plane_strain, tr, ntr, sys, err, u_prescribed=u_prescribed, &
                       body_force=body_force)
    call error_parts(err, info, msg)
    call solve_full(sys, info, msg, 'assemble_body', u_full)
  end subroutine solve_body

  !> Body `id`, the rectangle [x0, x0+width] x [y0, y0+height] on an nx x ny grid of
  !! `element`; material young, poisson where given, else the type's defaults; sides free.
  function rect_body(id, x0, y0, width, height, nx, ny, element, young, poisson) result(body)
    integer, intent(in) :: id, nx, ny, element
    real(wp), intent(in) :: x0, y0, width, height
    real(wp), intent(in), optional :: young, poisson
    type(body_cfg_t) :: body
    body%id = id
    body%x0 = x0
    body%y0 = y0
    body%width = width
    body%height = height
    body%nx = nx
    body%ny = ny
    body%element = element
    if (present(young)) body%young = young
    if (present(poisson)) body%poisson = poisson
  end function rect_body

  !> The body of the assembly tests and its mesh: id 1, (-0.4, 0.3) + 2.5 x 1.2 on nx x ny
  !! cells of `element`, E = 70, nu = 0.33; left clamped, right moved by (0.01, -0.02),
  !! bottom on rollers, top free and loaded by t0 = (0.3, -1).
  subroutine loaded_rect(element, nx, ny, body, tr, m)
    integer, intent(in) :: element, nx, ny
    type(body_cfg_t), intent(out) :: body
    type(traction_cfg_t), intent(out) :: tr
    type(mesh_t), intent(out) :: m
    body = rect_body(1, -0.4_wp, 0.3_wp, 2.5_wp, 1.2_wp, nx, ny, element, young=70.0_wp, poisson=0.33_wp)
    body%bc(1:4) = [BC_CLAMPED, BC_DISPLACEMENT, BC_ROLLER, BC_FREE]
    body%u_side(1:2, SIDE_RIGHT) = [0.01_wp, -0.02_wp]
    tr%body = 1
    tr%side = SIDE_TOP
    tr%t0(1:2) = [0.3_wp, -1.0_wp]
    call grid_mesh(m, body)
  end subroutine loaded_rect

  !> Deterministic pseudo-random number in [-0.5, 0.5) for integer pair (i, j).
  pure real(wp) function hash01(i, j)
    integer, intent(in) :: i, j
    real(wp) :: v
    v = sin(12.9898_wp*real(i, wp) + 78.233_wp*real(j, wp) + 0.5_wp)*43758.5453_wp
    hash01 = v - floor(v) - 0.5_wp
  end function hash01

  !> Move every interior node by up to +-frac/2 of a cell size in x and y.
  subroutine distort_interior(m, frac)
    type(mesh_t), intent(inout) :: m
    real(wp), intent(in) :: frac
    integer :: i, j, k
    real(wp) :: hx, hy
    hx = m%width/m%nx
    hy = m%height/m%ny
    do j = 1, m%ny - 1
      do i = 1, m%nx - 1
        k = 1 + i + j*(m%nx + 1)
        m%xy(1, k) = m%xy(1, k) + frac*hx*hash01(i, j)
        m%xy(2, k) = m%xy(2, k) + frac*hy*hash01(j + 17, i + 5)
      end do
    end do
  end subroutine distort_interior

  ! ---------------------------------------------------------------------------------
  !> CSC structure: counts, sorted rows, symmetry, matvec against the element loop,
  !! the lifting of prescribed values, rigid-body modes.
  !> The distributed assembly of the MPI binary: the cells split in nparts consecutive
  !! shares (as ranks r of a body's group take them), each share's triplets
  !! (cell_triplets) summed add up to the serial matrix's lower triangle; assemble_body
  !! with matrix=.false. gives the same DOF numbering and load without a matrix.
  subroutine test_triplets(element, nparts)
    integer, intent(in) :: element, nparts
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys, sys0
    type(traction_cfg_t) :: tr(1)
    integer :: info, r, q, j, p
    type(error_t) :: err
    integer, allocatable :: irn(:), jcn(:)
    real(wp), allocatable :: a(:), dense(:, :), ref(:, :)
    character(len=256) :: msg
    character(len=32) :: what

    write (what, '(a,a,i0,a)') trim(element_names(element)), ' ', nparts, ' shares:'
    call loaded_rect(element, 7, 4, body, tr(1), m)
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    call assemble_body(m, body, .true., tr, 1, sys0, err, matrix=.false.)
    call error_parts(err, info, msg)
    call report(info == 0 .and. .not. allocated(sys0%val) .and. sys0%n == sys%n .and. &
                all(sys0%free_of == sys%free_of) .and. maxval(abs(sys0%f - sys%f)) <= 1.0e-14_wp*maxval(abs(sys%f)), &
                trim(what)//' assemble_body(matrix=.false.): same numbering and load, no matrix')
    allocate (dense(sys%n, sys%n), ref(sys%n, sys%n))
    dense = 0.0_wp
    ref = 0.0_wp
    do j = 1, sys%n
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        if (sys%rowind(p) + 1 >= j) ref(sys%rowind(p) + 1, j) = sys%val(p)
      end do
    end do
    do r = 0, nparts - 1
      call cell_triplets(m, body, .true., sys0, r*m%ncell/nparts + 1, (r + 1)*m%ncell/nparts, irn, jcn, a, err)
      call error_parts(err, info, msg)
      if (info /= 0 .or. any(irn < jcn)) then
        call report(.false., trim(what)//' cell_triplets info = 0, lower triangle only')
        return
      end if
      do q = 1, size(a)
        dense(irn(q), jcn(q)) = dense(irn(q), jcn(q)) + a(q)
      end do
    end do
    call report(maxval(abs(dense - ref)) <= 1.0e-13_wp*maxval(abs(ref)), trim(what)// &
                ' the shares add up to the serial matrix (lower triangle)', maxval(abs(dense - ref))/maxval(abs(ref)), 1.0e-13_wp)
  end subroutine test_triplets

  !> The Q1 element stiffness equals, bit for bit, the plain 2x2 Gauss sum over
  !! q1_gradients (w = det at each point, entries added as ke + c11 xa xb + mu ya yb, ...),
  !! on random convex quadrilaterals and on a self-crossing one (negative Jacobians).
  subroutine test_q1_stiffness_bits()
    real(wp), parameter :: lam = 1.7e5_wp, mu = 0.93e5_wp
    real(wp), parameter :: gp2 = 0.577350269189625764509148780502_wp   ! 1/sqrt(3), as module elements
    real(wp) :: xe(2, MAX_NVERT), ke(MAX_NDOF, MAX_NDOF), ref(MAX_NDOF, MAX_NDOF), minjac, refjac
    real(wp) :: nfun(4), g(2, MAX_NVERT), det, r(2, 4), c11, xa, ya, xb, yb
    integer :: t, ig, jg, a, b, bad
    bad = 0
    call random_seed(put=[(12345 + 7*t, t=1, 64)])
    c11 = lam + 2.0_wp*mu
    do t = 1, 2001
      call random_number(r)
      xe(:, 1) = [0.0_wp, 0.0_wp] + 0.3_wp*r(:, 1)
      xe(:, 2) = [1.0_wp, 0.0_wp] + 0.3_wp*r(:, 2)
      xe(:, 3) = [1.0_wp, 1.0_wp] + 0.3_wp*r(:, 3)
      xe(:, 4) = [0.0_wp, 1.0_wp] + 0.3_wp*r(:, 4)
      xe = 1.0e3_wp*r(1, 1)*xe + 37.0_wp*r(2, 2)
      if (t == 2001) xe = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], [2, 4])
      call element_stiffness(ELEM_Q1, xe, lam, mu, ke, minjac)
      ref = 0.0_wp
      refjac = huge(1.0_wp)
      do jg = -1, 1, 2
        do ig = -1, 1, 2
          call q1_gradients(xe, ig*gp2, jg*gp2, nfun, g, det)
          refjac = min(refjac, det)
          if (.not. (det > 0.0_wp)) cycle
          do b = 1, 4
            xb = g(1, b)*det
            yb = g(2, b)*det
            do a = 1, 4
              xa = g(1, a)
              ya = g(2, a)
              ref(2*a - 1, 2*b - 1) = ref(2*a - 1, 2*b - 1) + c11*xa*xb + mu*ya*yb
              ref(2*a, 2*b - 1) = ref(2*a, 2*b - 1) + lam*ya*xb + mu*xa*yb
              ref(2*a - 1, 2*b) = ref(2*a - 1, 2*b) + lam*xa*yb + mu*ya*xb
              ref(2*a, 2*b) = ref(2*a, 2*b) + c11*ya*yb + mu*xa*xb
            end do
          end do
        end do
      end do
      if (any(ke /= ref) .or. .not. (minjac == refjac)) bad = bad + 1
    end do
    call report(bad == 0, 'Q1 element stiffness: the 2x2 Gauss sum over q1_gradients bit for bit '// &
                '(2000 random quadrilaterals and a self-crossing one), mismatches', real(bad, wp), 0.0_wp)
  end subroutine test_q1_stiffness_bits

  !> A mesh that is not structured is assembled at the places its pattern recorded for
  !! each cell, the grid by searching each column's rows: the grid of loaded_rect and a
  !! copy of it marked general with its nodes renumbered (k -> 17 (k - 1) mod nnode + 1),
  !! held by named groups as loaded_rect's sides (left clamped, right displaced, bottom on
  !! rollers: some nodes have one free DOF), give the same matrix and lifting bit for bit,
  !! each entry being the same cells' sum in the same order.
  subroutine test_general_scatter(element)
    integer, intent(in) :: element
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(1)
    type(mesh_t) :: m, g
    type(body_system_t) :: s1, s2
    type(error_t) :: err
    type(boundary_cfg_t) :: bnd(3)
    integer, allocatable :: perm(:), fmap(:)
    real(wp), allocatable :: k1(:, :), k2(:, :)
    integer :: info, k, c, d, e, i, nbad
    character(len=256) :: msg
    character(len=5) :: en

    en = element_names(element)
    call loaded_rect(element, 7, 4, body, tr(1), m)
    body%bc = BC_FREE
    bnd(:)%body = 1
    bnd(1)%group = 'left'
    bnd(1)%fix = .true.
    bnd(2)%group = 'right'
    bnd(2)%fix = .true.
    bnd(2)%u(1:2) = [0.01_wp, -0.02_wp]
    bnd(3)%group = 'bottom'
    bnd(3)%fix(1:2) = [.false., .true.]
    g = m
    g%structured = .false.
    allocate (perm(m%nnode))
    do k = 1, m%nnode
      perm(k) = mod(17*(k - 1), m%nnode) + 1
    end do
    g%xy(:, perm) = m%xy
    do c = 1, m%ncell
      g%cells(1:m%nvert, c) = perm(m%cells(1:m%nvert, c))
    end do
    do i = 1, g%ngroup
      do e = 1, g%group(i)%nedge
        g%group(i)%edge(:, e) = perm(m%group(i)%edge(:, e))
      end do
      if (g%group(i)%nnode > 0) g%group(i)%node = perm(m%group(i)%node)
    end do
    call assemble_body(m, body, .true., tr, 0, s1, err, boundaries=bnd)
    call error_parts(err, info, msg)
    if (info == 0) call assemble_body(g, body, .true., tr, 0, s2, err, boundaries=bnd)
    call error_parts(err, info, msg)
    if (info /= 0 .or. s1%n /= s2%n) then
      call report(.false., trim(en)//' general numbering: assembled, same free DOF count')
      return
    end if
    ! free index of the grid -> free index of the renumbered copy
    allocate (fmap(s1%n))
    do i = 1, s1%n
      d = s1%dof_of(i)
      k = (d + 1)/2
      fmap(i) = s2%free_of(2*(perm(k) - 1) + d - 2*(k - 1))
    end do
    k1 = dense_of(s1)
    k2 = dense_of(s2)
    nbad = count(k1 /= k2(fmap, fmap)) + count(s1%f /= s2%f(fmap))
    call report(all(fmap > 0) .and. s1%colptr(s1%n + 1) == s2%colptr(s2%n + 1) .and. nbad == 0 .and. &
                any(s1%f /= 0.0_wp) .and. count(s1%free_of(2::2) == 0) > count(s1%free_of(1::2) == 0), &
                trim(en)//' general mesh, nodes renumbered: the same matrix and lifting as the grid, bit for bit '// &
                '(entries that differ)', real(nbad, wp), 0.0_wp)
  end subroutine test_general_scatter

  !> A mixed mesh (the grid of loaded_rect, every third cell split into two triangles):
  !! its assembled lower triangle equals, bit for bit, the sum in cell order of its cells'
  !! triplets (cell_triplets), and every column's rows are sorted.
  subroutine test_mixed_scatter()
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(1)
    type(mesh_t) :: m, g
    type(body_system_t) :: sys
    type(error_t) :: err
    integer :: info, c, n, nbad, ntri
    character(len=256) :: msg

    call loaded_rect(ELEM_Q1, 7, 4, body, tr(1), m)
    ntri = 0
    do c = 1, m%ncell
      if (mod(c, 3) == 0) ntri = ntri + 1
    end do
    g = m
    g%structured = .false.
    g%element = ELEM_MIXED
    g%ncell = m%ncell + ntri
    deallocate (g%cells, g%cell_tag)
    if (allocated(g%cell_type)) deallocate (g%cell_type)
    allocate (g%cells(4, g%ncell), g%cell_type(g%ncell), g%cell_tag(g%ncell))
    n = 0
    do c = 1, m%ncell
      if (mod(c, 3) == 0) then
        g%cells(:, n + 1) = [m%cells(1:3, c), 0]
        g%cells(:, n + 2) = [m%cells(1, c), m%cells(3:4, c), 0]
        g%cell_type(n + 1:n + 2) = ELEM_P1
        n = n + 2
      else
        g%cells(:, n + 1) = m%cells(:, c)
        g%cell_type(n + 1) = ELEM_Q1
        n = n + 1
      end if
    end do
    g%cell_tag = [(c, c=1, g%ncell)]
    call assemble_body(g, body, .true., tr, 0, sys, err)
    call error_parts(err, info, msg)
    nbad = -1
    if (info == 0) nbad = triplet_mismatch(g, body, sys)
    call report(nbad == 0, 'mixed general mesh (Q1 and P1 cells): rows sorted, the lower triangle '// &
                'is the sum of the cells'' triplets bit for bit (entries that differ)', real(nbad, wp), 0.0_wp)
  end subroutine test_mixed_scatter

  !> A fan of 16,400 triangles around one node, one rim edge clamped: the centre's
  !! columns have 32,798 rows, more than 16-bit offsets hold, so the cells' places are not
  !! recorded and each column's rows are searched; the lower triangle is still the sum of
  !! the cells' triplets bit for bit.
  subroutine test_fan_scatter()
    integer, parameter :: nfan = 16400
    real(wp), parameter :: pi = acos(-1.0_wp)
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(1)
    type(boundary_cfg_t) :: bnd(1)
    type(mesh_t) :: g
    type(body_system_t) :: sys
    type(error_t) :: err
    integer :: info, i, nbad, longest
    character(len=256) :: msg

    body = rect_body(1, 0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 1, 1, ELEM_P1, young=70.0_wp, poisson=0.33_wp)
    g%structured = .false.
    g%element = ELEM_P1
    g%nvert = 3
    g%nnode = nfan + 1
    g%ncell = nfan
    allocate (g%xy(2, g%nnode), g%cells(3, g%ncell), g%cell_tag(g%ncell), g%node_tag(g%nnode))
    g%xy(:, 1) = 0.0_wp
    do i = 1, nfan
      g%xy(:, i + 1) = [cos(2.0_wp*pi*(i - 1)/nfan), sin(2.0_wp*pi*(i - 1)/nfan)]
      g%cells(:, i) = [1, i + 1, mod(i, nfan) + 2]
    end do
    g%cell_tag = [(i, i=1, g%ncell)]
    g%node_tag = [(i, i=1, g%nnode)]
    g%ngroup = 1
    allocate (g%group(1))
    g%group(1)%name = 'rim'
    g%group(1)%nedge = 1
    g%group(1)%edge = reshape([2, 3], [2, 1])
    g%group(1)%cell = [1]
    bnd(1)%body = 1
    bnd(1)%group = 'rim'
    bnd(1)%fix = .true.
    call assemble_body(g, body, .true., tr, 0, sys, err, boundaries=bnd)
    call error_parts(err, info, msg)
    nbad = -1
    longest = 0
    if (info == 0) then
      nbad = triplet_mismatch(g, body, sys)
      longest = maxval(sys%colptr(2:) - sys%colptr(:sys%n))
    end if
    call report(nbad == 0 .and. longest > huge(0_int16), 'fan of 16,400 triangles (a column longer than 16-bit '// &
                'offsets): the lower triangle is the sum of the cells'' triplets bit for bit (entries that differ)', &
                real(nbad, wp), 0.0_wp)
  end subroutine test_fan_scatter

  !> How many lower-triangle entries of sys differ from the sum, in cell order, of the
  !! cells' triplets (cell_triplets); -1 when the triplets fail, a column's rows are not
  !! strictly increasing, or a triplet falls outside the pattern.
  integer function triplet_mismatch(g, body, sys) result(nbad)
    type(mesh_t), intent(in) :: g
    type(body_cfg_t), intent(in) :: body
    type(body_system_t), intent(in) :: sys
    type(error_t) :: err
    integer, allocatable :: irn(:), jcn(:)
    real(wp), allocatable :: a(:), ref(:)
    integer :: q, j, lo, hi, mid, info
    character(len=256) :: msg
    nbad = -1
    call cell_triplets(g, body, .true., sys, 1, g%ncell, irn, jcn, a, err)
    call error_parts(err, info, msg)
    if (info /= 0) return
    do j = 1, sys%n
      do q = sys%colptr(j) + 1, sys%colptr(j + 1) - 1
        if (sys%rowind(q) >= sys%rowind(q + 1)) return
      end do
    end do
    allocate (ref(size(sys%val)))
    ref = 0.0_wp
    do q = 1, size(a)
      lo = sys%colptr(jcn(q)) + 1
      hi = sys%colptr(jcn(q) + 1)
      do while (lo < hi)
        mid = (lo + hi)/2
        if (sys%rowind(mid) < irn(q) - 1) then
          lo = mid + 1
        else
          hi = mid
        end if
      end do
      if (lo > sys%colptr(jcn(q) + 1)) return
      if (sys%rowind(lo) /= irn(q) - 1) return
      ref(lo) = ref(lo) + a(q)
    end do
    nbad = 0
    do j = 1, sys%n
      do q = sys%colptr(j) + 1, sys%colptr(j + 1)
        if (sys%rowind(q) + 1 >= j .and. sys%val(q) /= ref(q)) nbad = nbad + 1
      end do
    end do
  end function triplet_mismatch

  !> The assembled stiffness as a dense matrix (n x n).
  function dense_of(sys) result(kd)
    type(body_system_t), intent(in) :: sys
    real(wp), allocatable :: kd(:, :)
    integer :: j, p
    allocate (kd(sys%n, sys%n))
    kd = 0.0_wp
    do j = 1, sys%n
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        kd(sys%rowind(p) + 1, j) = sys%val(p)
      end do
    end do
  end function dense_of

  subroutine test_structure(element)
    integer, intent(in) :: element
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    integer :: info, i, j, p, q, nnz_expect, k
    type(error_t) :: err
    character(len=256) :: msg
    character(len=5) :: en
    logical :: sorted, found
    real(wp) :: asym, diff, scale, x(200), y(200), lame_lambda, lame_mu, x0, x1, y0, y1, ix2, iy2, ixy, energy
    real(wp), allocatable :: uf(:), r(:), u(:)

    en = element_names(element)
    call loaded_rect(element, 5, 3, body, tr(1), m)
    tr(1)%t1(1:2) = [0.0_wp, 0.5_wp]
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    call report(info == 0, trim(en)//' assemble_body info = 0 on a valid body', real(info, wp), 0.0_wp)

    ! 6 x 4 nodes = 48 dofs; left clamped 8, bottom roller 5 more y's, right both 8
    ! minus the bottom-right y already prescribed: 7; free 48 - 20 = 28.
    call report(sys%n == 28, trim(en)//' free dof count (expect 28)', real(sys%n, wp), 0.0_wp)
    call report(sys%u_fixed(2*6) == 0.0_wp .and. sys%u_fixed(2*6 - 1) == 0.01_wp, &
                trim(en)//' corner rule: bottom-right y takes the later side (roller, 0)', sys%u_fixed(2*6), 0.0_wp)

    ! nnz from first principles: count couplings between free dofs through cells.
    nnz_expect = count_couplings(m, sys)
    call report(sys%colptr(sys%n + 1) == nnz_expect, &
                trim(en)//' nnz equals the free-free couplings through cells', &
                real(sys%colptr(sys%n + 1), wp), real(nnz_expect, wp))

    sorted = .true.
    asym = 0.0_wp
    do j = 1, sys%n
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        if (p > sys%colptr(j) + 1) then
          if (sys%rowind(p) <= sys%rowind(p - 1)) sorted = .false.
        end if
        i = sys%rowind(p) + 1
        found = .false.
        do q = sys%colptr(i) + 1, sys%colptr(i + 1)
          if (sys%rowind(q) + 1 == j) then
            found = .true.
            asym = max(asym, abs(sys%val(q) - sys%val(p)))
          end if
        end do
        if (.not. found) asym = huge(1.0_wp)
      end do
    end do
    call report(sorted, trim(en)//' rows strictly increasing in every column', 0.0_wp, 0.0_wp)
    call report(asym <= 10*eps*sys%k_norm, &
                trim(en)//' pattern and values symmetric (max |Kij-Kji|/|K|)', asym/sys%k_norm, 10*eps)

    ! Matvec on free dofs + lifting against the element loop on all dofs:
    ! (K_full u_full - f_applied)_free = K_ff u_f - f.
    do k = 1, sys%n
      x(k) = hash01(k, 3)
    end do
    allocate (uf(sys%ndof), r(sys%ndof))
    call expand(sys, x(1:sys%n), uf)
    call residual_full(m, body, .true., uf, sys%f_applied, r)
    call csc_matvec(sys, x(1:sys%n), y(1:sys%n))
    diff = 0.0_wp
    do k = 1, sys%n
      diff = max(diff, abs(r(sys%dof_of(k)) - (y(k) - sys%f(k))))
    end do
    scale = sys%k_norm*maxval(abs(uf)) + maxval(abs(sys%f_applied))
    call report(diff <= 100*eps*scale, &
                trim(en)//' csc_matvec and lifting agree with the element loop', diff/scale, 100*eps)

    ! k_norm is the infinity norm: at least every |K_jj|, at most the sum of all entries.
    call report(sys%k_norm >= maxval(abs(sys%val))*(1 - eps) .and. sys%k_norm <= sum(abs(sys%val)), &
                trim(en)//' k_norm between max |K_jj| and sum |K_ij|', sys%k_norm, 0.0_wp)

    ! Rigid-body modes produce no force.
    allocate (u(sys%ndof))
    uf = 0.0_wp
    do k = 1, m%nnode
      u(2*k - 1) = 0.3_wp - 0.7_wp*m%xy(2, k)
      u(2*k) = -1.1_wp + 0.7_wp*m%xy(1, k)
    end do
    call residual_full(m, body, .true., u, uf, r)
    call report(maxval(abs(r)) <= 100*eps*sys%k_norm*maxval(abs(u)), &
                trim(en)//' rigid-body motion gives zero nodal forces', &
                maxval(abs(r))/(sys%k_norm*maxval(abs(u))), 100*eps)

    ! Q1: the bilinear field u = (xy, xy) is in the element space; its strain energy
    ! u'Ku must equal the exact integral of lambda (tr eps)^2 + 2 mu eps:eps (this checks the
    ! quadrature of the element stiffness, which the patch test cannot see).
    if (element == ELEM_Q1) then
      do k = 1, m%nnode
        u(2*k - 1) = m%xy(1, k)*m%xy(2, k)
        u(2*k) = m%xy(1, k)*m%xy(2, k)
      end do
      call residual_full(m, body, .true., u, uf, r)
      lame_mu = body%young/(2*(1 + body%poisson))
      lame_lambda = body%young*body%poisson/((1 + body%poisson)*(1 - 2*body%poisson))
      x0 = body%x0
      x1 = body%x0 + body%width
      y0 = body%y0
      y1 = body%y0 + body%height
      ix2 = (y1 - y0)*(x1**3 - x0**3)/3
      iy2 = (x1 - x0)*(y1**3 - y0**3)/3
      ixy = (x1**2 - x0**2)*(y1**2 - y0**2)/4
      energy = (lame_lambda + lame_mu)*(ix2 + iy2 + 2*ixy) + 2*lame_mu*(ix2 + iy2)
      diff = abs(dot_product(u, r) - energy)
      call report(diff <= 1.0e-13_wp*energy, &
                  trim(en)//' strain energy of a bilinear field is exact (rel err)', diff/energy, 1.0e-13_wp)
    end if
  end subroutine test_structure

  !> Number of (free row, free column) pairs of dofs sharing at least one cell.
  integer function count_couplings(m, sys) result(cnt)
    type(mesh_t), intent(in) :: m
    type(body_system_t), intent(in) :: sys
    logical, allocatable :: adj(:, :)
    integer :: c, a, b
    allocate (adj(m%nnode, m%nnode))
    adj = .false.
    do c = 1, m%ncell
      do a = 1, m%nvert
        do b = 1, m%nvert
          adj(m%cells(a, c), m%cells(b, c)) = .true.
        end do
      end do
    end do
    cnt = 0
    do b = 1, sys%ndof
      if (sys%free_of(b) == 0) cycle
      do a = 1, sys%ndof
        if (sys%free_of(a) == 0) cycle
        if (adj((a - 1)/2 + 1, (b - 1)/2 + 1)) cnt = cnt + 1
      end do
    end do
  end function count_couplings

  ! ---------------------------------------------------------------------------------
  !> Patch test: a linear field prescribed on the boundary of a distorted mesh is
  !! reproduced inside, and its stress is the constant D eps.
  subroutine test_patch(element, plane_strain)
    integer, intent(in) :: element
    logical, intent(in) :: plane_strain
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    real(wp), allocatable :: u_ex(:), u(:), sigma(:, :), vm(:)
    real(wp) :: a(0:2), b(0:2), e, nu, lame_lambda, lame_mu, exx, eyy, gxy, s_ex(4), vm_ex, err, umax
    integer :: k, i, j
    character(len=32) :: what

    write (what, '(a,a,a)') element_names(element), ' ', merge('plane strain', 'plane stress', plane_strain)
    a = [1.0e-3_wp, 2.0e-3_wp, -1.0e-3_wp]
    b = [-5.0e-4_wp, 1.5e-3_wp, 3.0e-3_wp]
    body = rect_body(1, 0.2_wp, -0.3_wp, 1.2_wp, 1.0_wp, 6, 5, element, young=200.0_wp, poisson=0.3_wp)
    body%bc = BC_CLAMPED
    e = body%young
    nu = body%poisson

    call grid_mesh(m, body)
    call distort_interior(m, 0.3_wp)
    allocate (u_ex(2*m%nnode))
    do k = 1, m%nnode
      u_ex(2*k - 1) = a(0) + a(1)*m%xy(1, k) + a(2)*m%xy(2, k)
      u_ex(2*k) = b(0) + b(1)*m%xy(1, k) + b(2)*m%xy(2, k)
    end do
    call solve_body(m, body, plane_strain, tr, 0, sys, u, u_prescribed=u_ex)

    err = 0.0_wp
    do j = 1, m%ny - 1
      do i = 1, m%nx - 1
        k = 1 + i + j*(m%nx + 1)
        err = max(err, abs(u(2*k - 1) - u_ex(2*k - 1)), abs(u(2*k) - u_ex(2*k)))
      end do
    end do
    umax = maxval(abs(u_ex))
    call report(err <= 1.0e-12_wp*umax, &
                'patch '//trim(what)//': interior displacements (max rel err)', err/umax, 1.0e-12_wp)

    ! Stress of the linear field, from the textbook moduli (independent of module assembly).
    lame_mu = e/(2*(1 + nu))
    if (plane_strain) then
      lame_lambda = e*nu/((1 + nu)*(1 - 2*nu))
    else
      lame_lambda = e*nu/(1 - nu**2)
    end if
    exx = a(1)
    eyy = b(2)
    gxy = a(2) + b(1)
    s_ex(1) = (lame_lambda + 2*lame_mu)*exx + lame_lambda*eyy
    s_ex(2) = lame_lambda*exx + (lame_lambda + 2*lame_mu)*eyy
    s_ex(3) = lame_mu*gxy
    s_ex(4) = merge(nu*(s_ex(1) + s_ex(2)), 0.0_wp, plane_strain)
    vm_ex = sqrt(0.5_wp*((s_ex(1) - s_ex(2))**2 + (s_ex(2) - s_ex(4))**2 + (s_ex(4) - s_ex(1))**2) &
                 + 3*s_ex(3)**2)
    allocate (sigma(4, m%nnode), vm(m%nnode))
    call nodal_stress(m, body, plane_strain, u, sigma, vm)
    err = 0.0_wp
    do k = 1, m%nnode
      err = max(err, maxval(abs(sigma(:, k) - s_ex)))
    end do
    call report(err <= 1.0e-11_wp*maxval(abs(s_ex)), &
                'patch '//trim(what)//': nodal stress = D eps (max rel err)', &
                err/maxval(abs(s_ex)), 1.0e-11_wp)
    err = maxval(abs(vm - vm_ex))
    call report(err <= 1.0e-11_wp*vm_ex, &
                'patch '//trim(what)//': von Mises (max rel err)', err/vm_ex, 1.0e-11_wp)
  end subroutine test_patch

  ! ---------------------------------------------------------------------------------
  !> Shape functions, x-y gradients, position and Jacobian of cell c at reference
  !! point (r, s): Q1 on [-1,1]^2, P1 on the unit triangle (own implementation).
  subroutine eval_cell(m, c, r, s, nf, g, xq, det)
    type(mesh_t), intent(in) :: m
    integer, intent(in) :: c
    real(wp), intent(in) :: r, s
    real(wp), intent(out) :: nf(4), g(2, 4), xq(2), det
    real(wp) :: dr(4), ds(4), jac(2, 2), xe(2, 4)
    integer :: a, nv
    nv = m%nvert
    do a = 1, nv
      xe(:, a) = m%xy(:, m%cells(a, c))
    end do
    if (nv == 4) then
      nf = 0.25_wp*[(1 - r)*(1 - s), (1 + r)*(1 - s), (1 + r)*(1 + s), (1 - r)*(1 + s)]
      dr = 0.25_wp*[-(1 - s), (1 - s), (1 + s), -(1 + s)]
      ds = 0.25_wp*[-(1 - r), -(1 + r), (1 + r), (1 - r)]
    else
      nf = [1 - r - s, r, s, 0.0_wp]
      dr = [-1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp]
      ds = [-1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp]
    end if
    jac(1, 1) = sum(dr(1:nv)*xe(1, 1:nv))
    jac(1, 2) = sum(dr(1:nv)*xe(2, 1:nv))
    jac(2, 1) = sum(ds(1:nv)*xe(1, 1:nv))
    jac(2, 2) = sum(ds(1:nv)*xe(2, 1:nv))
    det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
    g = 0.0_wp
    do a = 1, nv
      g(1, a) = (jac(2, 2)*dr(a) - jac(1, 2)*ds(a))/det
      g(2, a) = (-jac(2, 1)*dr(a) + jac(1, 1)*ds(a))/det
    end do
    xq = matmul(xe(:, 1:nv), nf(1:nv))
  end subroutine eval_cell

  !> L2 and H1-seminorm errors against the manufactured u, 5x5 Gauss on Q1 cells and
  !! a collapsed (Duffy) 5x5 Gauss rule on P1 cells (exact to degree 9 and 8).
  subroutine ms_errors(m, u, el2, eh1)
    type(mesh_t), intent(in) :: m
    real(wp), intent(in) :: u(:)
    real(wp), intent(out) :: el2, eh1
    real(wp), parameter :: gx(5) = [-0.906179845938663992797626878299_wp, -0.538469310105683091036314420700_wp, &
                                    0.0_wp, 0.538469310105683091036314420700_wp, 0.906179845938663992797626878299_wp]
    real(wp), parameter :: gw(5) = [0.236926885056189087514264040720_wp, 0.478628670499366468041291514836_wp, &
                                    0.568888888888888888888888888889_wp, 0.478628670499366468041291514836_wp, &
                                    0.236926885056189087514264040720_wp]
    integer :: c, ig, jg, a, k
    real(wp) :: r, s, w, nf(4), g(2, 4), xq(2), det, ue(2), ge(2, 2), uh(2), gh(2, 2)
    el2 = 0.0_wp
    eh1 = 0.0_wp
    do c = 1, m%ncell
      do jg = 1, 5
        do ig = 1, 5
          if (m%nvert == 4) then
            r = gx(ig)
            s = gx(jg)
            w = gw(ig)*gw(jg)
          else
            r = 0.5_wp*(1 + gx(ig))
            s = 0.5_wp*(1 + gx(jg))*(1 - r)
            w = 0.25_wp*gw(ig)*gw(jg)*(1 - r)
          end if
          call eval_cell(m, c, r, s, nf, g, xq, det)
          call ms_u(xq(1), xq(2), ue, ge)
          uh = 0.0_wp
          gh = 0.0_wp
          do a = 1, m%nvert
            k = m%cells(a, c)
            uh = uh + nf(a)*u(2*k - 1:2*k)
            gh(:, 1) = gh(:, 1) + g(1, a)*u(2*k - 1:2*k)
            gh(:, 2) = gh(:, 2) + g(2, a)*u(2*k - 1:2*k)
          end do
          el2 = el2 + w*det*sum((uh - ue)**2)
          eh1 = eh1 + w*det*sum((gh - ge)**2)
        end do
      end do
    end do
    el2 = sqrt(el2)
    eh1 = sqrt(eh1)
  end subroutine ms_errors

  !> Observed convergence rates against the manufactured solution (Dirichlet on the
  !! whole boundary, body force from the optional callback of assemble_body).
  subroutine test_manufactured(element)
    integer, intent(in) :: element
    integer, parameter :: nlev = 5
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    real(wp) :: el2(nlev), eh1(nlev), rl2, rh1, ue(2), ge(2, 2)
    real(wp), allocatable :: up(:), u(:)
    integer :: lev, k
    character(len=80) :: what

    body = rect_body(1, 0.5_wp, -0.25_wp, 1.5_wp, 1.0_wp, 4, 4, element, young=1.0_wp, poisson=0.3_wp)
    body%bc = BC_CLAMPED
    ms_lame_mu = body%young/(2*(1 + body%poisson))
    ms_lame_lambda = body%young*body%poisson/((1 + body%poisson)*(1 - 2*body%poisson))
    do lev = 1, nlev
      body%nx = 2**(lev + 1)
      body%ny = 2**(lev + 1)
      call grid_mesh(m, body)
      allocate (up(2*m%nnode))
      do k = 1, m%nnode
        call ms_u(m%xy(1, k), m%xy(2, k), ue, ge)
        up(2*k - 1:2*k) = ue
      end do
      call solve_body(m, body, .true., tr, 0, sys, u, u_prescribed=up, body_force=ms_force)
      call ms_errors(m, u, el2(lev), eh1(lev))
      write (*, '(a,a,1x,i3,a,i3,a,es11.4,a,es11.4)') '      manufactured ', element_names(element), &
        body%nx, ' x', body%ny, ': L2 error ', el2(lev), '  H1-seminorm error ', eh1(lev)
      deallocate (up, u)
    end do
    do lev = 2, nlev
      rl2 = log(el2(lev - 1)/el2(lev))/log(2.0_wp)
      rh1 = log(eh1(lev - 1)/eh1(lev))/log(2.0_wp)
      write (what, '(a,a,a,i0,a,i0)') 'manufactured ', element_names(element), ' L2 rate ', &
        2**lev, ' -> ', 2**(lev + 1)
      call report(rl2 >= 1.8_wp, trim(what)//' (>= 1.8)', rl2, 1.8_wp)
      write (what, '(a,a,a,i0,a,i0)') 'manufactured ', element_names(element), ' H1 rate ', &
        2**lev, ' -> ', 2**(lev + 1)
      call report(rh1 >= 0.9_wp, trim(what)//' (>= 0.9)', rh1, 0.9_wp)
    end do
  end subroutine test_manufactured

  ! ---------------------------------------------------------------------------------
  !> Consistent traction loads: resultant and first moment are exact, only side nodes
  !! are loaded.
  subroutine test_tractions(element)
    integer, intent(in) :: element
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(2)
    integer, allocatable :: nodes(:)
    integer :: side, info, k, coord, kase
    type(error_t) :: status
    character(len=256) :: msg
    character(len=80) :: what
    real(wp) :: sa, sb, fsum(2), fmom(2), fex(2), mex(2), err, scale, other
    real(wp), allocatable :: s_of(:)
    logical, allocatable :: onside(:)

    body = rect_body(2, 0.5_wp, 1.0_wp, 2.0_wp, 1.2_wp, 7, 5, element)
    body%bc = BC_FREE
    call grid_mesh(m, body)
    allocate (onside(m%nnode))
    do kase = 1, 2
      do side = 1, 4
        tr(1)%body = 2
        tr(1)%side = side
        if (kase == 1) then
          tr(1)%t0(1:2) = [1.3_wp, -0.7_wp]
          tr(1)%t1 = 0.0_wp
        else
          tr(1)%t0(1:2) = [0.4_wp, -1.1_wp]
          tr(1)%t1(1:2) = [2.5_wp, 0.8_wp]
        end if
        ! A traction on the other body must be ignored.
        tr(2)%body = 1
        tr(2)%side = SIDE_TOP
        tr(2)%t0(1:2) = [100.0_wp, 100.0_wp]
        call assemble_body(m, body, .false., tr, 2, sys, status)
        call error_parts(status, info, msg)
        if (info /= 0) then
          write (*, '(a,a)') 'FAIL  assemble_body: ', trim(msg)
          error stop 1
        end if
        call side_nodes(m, side, nodes)
        coord = merge(2, 1, side == SIDE_LEFT .or. side == SIDE_RIGHT)
        s_of = m%xy(coord, nodes)
        sa = s_of(1)
        sb = s_of(size(s_of))
        fsum = 0.0_wp
        fmom = 0.0_wp
        do k = 1, size(nodes)
          fsum = fsum + sys%f_applied(2*nodes(k) - 1:2*nodes(k))
          fmom = fmom + s_of(k)*sys%f_applied(2*nodes(k) - 1:2*nodes(k))
        end do
        onside = .false.
        onside(nodes) = .true.
        other = 0.0_wp
        do k = 1, m%nnode
          if (.not. onside(k)) other = max(other, maxval(abs(sys%f_applied(2*k - 1:2*k))))
        end do
        fex = tr(1)%t0(1:2)*(sb - sa) + tr(1)%t1(1:2)*(sb**2 - sa**2)/2
        mex = tr(1)%t0(1:2)*(sb**2 - sa**2)/2 + tr(1)%t1(1:2)*(sb**3 - sa**3)/3
        scale = (maxval(abs(tr(1)%t0)) + maxval(abs(tr(1)%t1))*max(abs(sa), abs(sb)))*(sb - sa)
        write (what, '(a,a,1x,a,1x,a)') 'traction ', element_names(element), &
          trim(merge('uniform', 'linear ', kase == 1)), trim(side_names(side))
        err = maxval(abs(fsum - fex))
        call report(err <= 20*eps*scale, trim(what)//': resultant exact', err/scale, 20*eps)
        err = maxval(abs(fmom - mex))
        call report(err <= 20*eps*scale*max(abs(sa), abs(sb)), &
                    trim(what)//': first moment exact', err/(scale*max(abs(sa), abs(sb))), 20*eps)
        call report(other == 0.0_wp, trim(what)//': no load off the side', other, 0.0_wp)
      end do
    end do
  end subroutine test_tractions

  ! ---------------------------------------------------------------------------------
  !> The same problem in SI (m, Pa) and in mm, N, MPa gives u_mm = 1e3 u_SI.
  subroutine test_units(element, plane_strain)
    integer, intent(in) :: element
    logical, intent(in) :: plane_strain
    type(body_cfg_t) :: b_si, b_mm
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: t_si(2), t_mm(2)
    real(wp), allocatable :: u_si(:), u_mm(:)
    real(wp) :: err, scale

    b_si = rect_body(1, 0.1_wp, 0.2_wp, 0.5_wp, 0.3_wp, 10, 6, element, young=7.0e10_wp, poisson=0.33_wp)
    b_si%bc(1:4) = [BC_CLAMPED, BC_DISPLACEMENT, BC_ROLLER, BC_FREE]
    b_si%u_side(1:2, SIDE_RIGHT) = [1.0e-4_wp, -2.0e-4_wp]
    t_si(1)%body = 1
    t_si(1)%side = SIDE_TOP
    t_si(1)%t0(1:2) = [1.0e6_wp, -2.0e7_wp]
    t_si(1)%t1(1:2) = [0.0_wp, 3.0e7_wp]
    t_si(2)%body = 1
    t_si(2)%side = SIDE_RIGHT
    t_si(2)%t0(1:2) = [5.0e6_wp, 0.0_wp]      ! on a prescribed side: reaches f_applied only

    b_mm = b_si
    b_mm%x0 = b_si%x0*1.0e3_wp
    b_mm%y0 = b_si%y0*1.0e3_wp
    b_mm%width = b_si%width*1.0e3_wp
    b_mm%height = b_si%height*1.0e3_wp
    b_mm%young = b_si%young*1.0e-6_wp
    b_mm%u_side = b_si%u_side*1.0e3_wp
    t_mm = t_si
    t_mm(1)%t0 = t_si(1)%t0*1.0e-6_wp
    t_mm(1)%t1 = t_si(1)%t1*1.0e-9_wp
    t_mm(2)%t0 = t_si(2)%t0*1.0e-6_wp

    call grid_mesh(m, b_si)
    call solve_body(m, b_si, plane_strain, t_si, 2, sys, u_si)
    call grid_mesh(m, b_mm)
    call solve_body(m, b_mm, plane_strain, t_mm, 2, sys, u_mm)
    scale = maxval(abs(u_mm))
    err = maxval(abs(u_mm - 1.0e3_wp*u_si))
    call report(err <= 1.0e-12_wp*scale, &
                'units '//element_names(element)//' '//merge('strain', 'stress', plane_strain)// ': u[mm] = 1e3 u[m] (max rel err)', &
                err/scale, 1.0e-12_wp)
  end subroutine test_units

  ! ---------------------------------------------------------------------------------
  !> Impossible inputs are reported through an error_t, not by stopping.
  subroutine test_errors()
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    real(wp) :: up(3)

    body%id = 1
    body%nx = 3
    body%ny = 2
    body%bc(SIDE_LEFT) = BC_CLAMPED
    call grid_mesh(m, body)
    tr(1)%body = 1
    tr(1)%side = 7
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    write (*, '(a,a)') '      message: ', trim(msg)
    call report(info /= 0 .and. len_trim(msg) > 0, &
                'errors: traction side 7 gives info /= 0 and a message', real(info, wp), 0.0_wp)
    call assemble_body(m, body, .true., tr, 2, sys, err)
    call error_parts(err, info, msg)
    call report(info /= 0, 'errors: ntraction > size(tractions) gives info /= 0', real(info, wp), 0.0_wp)
    tr(1)%side = SIDE_TOP
    body%poisson = 0.5_wp
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    call report(info /= 0, 'errors: Poisson ratio 0.5 gives info /= 0', real(info, wp), 0.0_wp)
    body%poisson = 0.3_wp
    body%bc(SIDE_TOP) = 9
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    call report(info /= 0, 'errors: unknown side condition gives info /= 0', real(info, wp), 0.0_wp)
    body%bc(SIDE_TOP) = BC_FREE
    up = 0.0_wp
    call assemble_body(m, body, .true., tr, 1, sys, err, u_prescribed=up)
    call error_parts(err, info, msg)
    call report(info /= 0, 'errors: u_prescribed of the wrong size gives info /= 0', real(info, wp), 0.0_wp)
    m%xy(1, 2) = m%xy(1, 2) + 2*body%width    ! fold a cell over
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    write (*, '(a,a)') '      message: ', trim(msg)
    call report(info /= 0, 'errors: an inverted cell gives info /= 0', real(info, wp), 0.0_wp)
    body%nx = 0
    call grid_mesh_parts(m, body, info, msg)
    call report(info /= 0 .and. m%nnode == 0, &
                'errors: mesh_build with nx = 0 gives an input error', real(info, wp), 0.0_wp)
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call error_parts(err, info, msg)
    call report(info /= 0, 'errors: assemble_body on an empty mesh gives info /= 0', real(info, wp), 0.0_wp)
  end subroutine test_errors

end program test_fem
