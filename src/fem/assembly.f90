!> Plane linear elasticity on a structured mesh (module mesh): the stiffness of one body
!! on its free DOFs in compressed sparse columns, the consistent load of its tractions,
!! elimination of prescribed displacements, reactions and nodal stresses.
!!
!! DOFs: node k, component c (1 = x, 2 = y) is global dof 2*(k-1)+c. Free DOFs are
!! numbered in increasing global order, so the stiffness on free DOFs keeps the natural
!! (band) structure of the grid. Isotropic material, plane strain or plane stress;
!! Q1 with 2x2 Gauss, P1 with one point (exact). Units are whatever the deck uses,
!! consistently: [length], [stress] = [force]/[length]^2, forces per unit thickness.
module assembly
  use kinds, only: wp, i8
  use config, only: body_cfg_t, traction_cfg_t, ELEM_Q1, ELEM_P1, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, side_names, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT
  use mesh, only: mesh_t, side_nodes
  implicit none
  private

  public :: assemble_body, expand, residual_full, nodal_stress, csc_matvec, lame_parameters
  public :: body_force_fn

  !> The linear system of one body on its free DOFs.
  type, public :: body_system_t
    integer :: id = 0                         !< body id
    integer :: ndof = 0                       !< 2*nnode
    integer :: n = 0                          !< number of free (unknown) DOFs
    integer, allocatable :: free_of(:)        !< (ndof) free index 1..n, or 0 if prescribed
    integer, allocatable :: dof_of(:)         !< (n) global dof of each free index
    real(wp), allocatable :: u_fixed(:)       !< (ndof) prescribed displacements, 0 at free dofs [length]
    integer, allocatable :: colptr(:)         !< (n+1) 0-based CSC column pointers of K (free dofs, both triangles)
    integer, allocatable :: rowind(:)         !< (nnz) 0-based row indices, sorted within each column
    real(wp), allocatable :: val(:)           !< (nnz) stiffness entries [stress] (force/length per unit thickness)
    real(wp), allocatable :: f(:)             !< (n) load on free dofs incl. the lifting -K_fd u_d [force]
    real(wp), allocatable :: f_applied(:)     !< (ndof) applied nodal loads (tractions, optional body force), all dofs [force]
    real(wp) :: k_norm = 0.0_wp               !< max abs row sum of K (infinity norm) [stress]
  end type body_system_t

  abstract interface
    !> A body force density b(x, y) [force/length^3] (per unit thickness: [force/length^2]/[length]).
    subroutine body_force_fn(x, y, b)
      import :: wp
      real(wp), intent(in) :: x            !< position x [length]
      real(wp), intent(in) :: y            !< position y [length]
      real(wp), intent(out) :: b(2)        !< body force density [force/length^3]
    end subroutine body_force_fn
  end interface

  real(wp), parameter :: xa_q1(4) = [-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp]  ! reference nodes of Q1
  real(wp), parameter :: ea_q1(4) = [-1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp]

  !> Cache of the last element stiffness: congruent cells (a uniform grid) reuse it.
  type :: ke_cache_t
    logical :: valid = .false.
    real(wp) :: rel(2, 4) = 0.0_wp   ! vertex coordinates relative to vertex 1
    real(wp) :: tol = 0.0_wp         ! coordinate tolerance below which cells are the same
    real(wp) :: ke(8, 8) = 0.0_wp
    real(wp) :: minjac = 0.0_wp
  end type ke_cache_t

contains

  !> Lame parameters of the body: plane strain uses lambda, mu; plane stress the
  !! reduced lambda* = 2 lambda mu / (lambda + 2 mu).
  pure subroutine lame_parameters(body, plane_strain, lam, mu)
    type(body_cfg_t), intent(in) :: body     !< young [stress], poisson [-]
    logical, intent(in) :: plane_strain      !< .true. plane strain, .false. plane stress
    real(wp), intent(out) :: lam             !< (effective) first Lame parameter [stress]
    real(wp), intent(out) :: mu              !< shear modulus [stress]
    real(wp) :: e, nu
    e = body%young
    nu = body%poisson
    mu = e/(2.0_wp*(1.0_wp + nu))
    if (plane_strain) then
      lam = e*nu/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
    else
      lam = e*nu/(1.0_wp - nu*nu)   ! = 2 lambda mu / (lambda + 2 mu)
    end if
  end subroutine lame_parameters

  !> Assemble the stiffness of one body on its free DOFs (CSC, full symmetric pattern) and
  !! its consistent load. Side conditions come from body%bc: clamped (both components 0),
  !! roller (normal component 0), displacement (both components = body%u_side(:,side)),
  !! free and contact (nothing). Prescribed DOFs are eliminated with the lifting
  !! f -= K_fd u_d. Tractions with %body == body%id are integrated exactly on the side.
  !! On an impossible input `info` is non-zero, `msg` says why, and `sys` is incomplete.
  subroutine assemble_body(mesh, body, plane_strain, tractions, ntraction, sys, info, msg, &
                           u_prescribed, body_force)
    type(mesh_t), intent(in) :: mesh                     !< the body's mesh (mesh_build)
    type(body_cfg_t), intent(in) :: body                 !< material, side conditions
    logical, intent(in) :: plane_strain                  !< .true. plane strain, .false. plane stress
    type(traction_cfg_t), intent(in) :: tractions(:)     !< tractions of the deck (any body)
    integer, intent(in) :: ntraction                     !< how many of `tractions` are in use
    type(body_system_t), intent(out) :: sys              !< the assembled system
    integer, intent(out) :: info                         !< 0 on success
    character(len=*), intent(out) :: msg                 !< error sentence when info /= 0
    !> (ndof) optional per-dof prescribed values [length]: where given, they replace the
    !! side values at every DOF that the side conditions prescribe (which DOFs are
    !! prescribed is still decided by body%bc).
    real(wp), intent(in), optional :: u_prescribed(:)
    !> optional body force density, integrated with 3x3 Gauss (Q1) or a degree-2 rule (P1)
    procedure(body_force_fn), optional :: body_force

    integer :: ndof, n, k, c, p, q, s, t, side, nv, nd, a, b, fc, pos, pend, nstencil
    integer :: i, j, ii, jj, m, cc, kk
    integer(i8) :: nnz
    integer, allocatable :: nodes(:)
    logical, allocatable :: pres(:)
    integer :: di(9), dj(9), ldof(8), lfree(8), perm(8)
    real(wp) :: lam, mu, xe(2, 4), ke(8, 8), ue(8), minjac, colsum
    logical :: lift
    type(ke_cache_t) :: cache

    info = 0
    msg = ''
    sys%id = body%id

    ! ---- check the arguments --------------------------------------------------------
    if (mesh%nnode < 1 .or. .not. allocated(mesh%xy) .or. .not. allocated(mesh%cells)) then
      info = 1
      write (msg, '(a,i0,a)') 'body ', body%id, ': the mesh is empty (call mesh_build first)'
      return
    end if
    if (mesh%element /= ELEM_Q1 .and. mesh%element /= ELEM_P1) then
      info = 1
      write (msg, '(a,i0,a,i0)') 'body ', body%id, ': unknown element code ', mesh%element
      return
    end if
    if (.not. (body%young > 0.0_wp)) then
      info = 2
      write (msg, '(a,i0,a,es12.4)') 'body ', body%id, ': Young''s modulus must be positive, got ', body%young
      return
    end if
    if (.not. (body%poisson > -1.0_wp .and. body%poisson < 0.5_wp)) then
      info = 2
      write (msg, '(a,i0,a,es12.4)') 'body ', body%id, ': Poisson''s ratio must lie in (-1, 0.5), got ', &
        body%poisson
      return
    end if
    do side = 1, 4
      if (body%bc(side) < BC_FREE .or. body%bc(side) > BC_DISPLACEMENT) then
        info = 3
        write (msg, '(a,i0,a,a,a,i0)') 'body ', body%id, ': unknown condition code on side ', &
          trim(side_names(side)), ': ', body%bc(side)
        return
      end if
    end do
    if (ntraction < 0 .or. ntraction > size(tractions)) then
      info = 4
      write (msg, '(a,i0,a,i0,a)') 'ntraction = ', ntraction, ' but only ', size(tractions), &
        ' tractions were passed'
      return
    end if
    do t = 1, ntraction
      if (tractions(t)%body /= body%id) cycle
      if (tractions(t)%side < SIDE_LEFT .or. tractions(t)%side > SIDE_TOP) then
        info = 4
        write (msg, '(a,i0,a,i0,a,i0,a)') 'traction ', t, ' on body ', body%id, &
          ' has side index ', tractions(t)%side, ', outside 1..4'
        return
      end if
    end do
    ndof = 2*mesh%nnode
    if (present(u_prescribed)) then
      if (size(u_prescribed) /= ndof) then
        info = 5
        write (msg, '(a,i0,a,i0,a,i0)') 'body ', body%id, ': u_prescribed has ', size(u_prescribed), &
          ' values, expected ndof = ', ndof
        return
      end if
    end if

    call lame_parameters(body, plane_strain, lam, mu)
    nv = mesh%nvert
    nd = 2*nv

    ! ---- prescribed DOFs ------------------------------------------------------------
    ! Sides are visited in SIDE_* order; a corner shared by two sides gets the union of
    ! their constraints, and where both prescribe the same component with different
    ! values the later side in SIDE_* order (left, right, bottom, top) wins.
    sys%ndof = ndof
    allocate (pres(ndof), sys%u_fixed(ndof))
    pres = .false.
    sys%u_fixed = 0.0_wp
    do side = 1, 4
      call side_nodes(mesh, side, nodes)
      select case (body%bc(side))
      case (BC_CLAMPED)
        do k = 1, size(nodes)
          do cc = 1, 2
            pres(2*(nodes(k) - 1) + cc) = .true.
            sys%u_fixed(2*(nodes(k) - 1) + cc) = 0.0_wp
          end do
        end do
      case (BC_ROLLER)
        cc = 1
        if (side == SIDE_BOTTOM .or. side == SIDE_TOP) cc = 2
        do k = 1, size(nodes)
          pres(2*(nodes(k) - 1) + cc) = .true.
          sys%u_fixed(2*(nodes(k) - 1) + cc) = 0.0_wp
        end do
      case (BC_DISPLACEMENT)
        do k = 1, size(nodes)
          do cc = 1, 2
            pres(2*(nodes(k) - 1) + cc) = .true.
            sys%u_fixed(2*(nodes(k) - 1) + cc) = body%u_side(cc, side)
          end do
        end do
      case default   ! BC_FREE, BC_CONTACT: nothing
      end select
    end do
    if (present(u_prescribed)) then
      where (pres) sys%u_fixed = u_prescribed
    end if

    allocate (sys%free_of(ndof))
    n = 0
    do k = 1, ndof
      if (pres(k)) then
        sys%free_of(k) = 0
      else
        n = n + 1
        sys%free_of(k) = n
      end if
    end do
    sys%n = n
    allocate (sys%dof_of(n))
    do k = 1, ndof
      if (sys%free_of(k) > 0) sys%dof_of(sys%free_of(k)) = k
    end do

    ! ---- sparsity pattern from the node stencil of the grid -------------------------
    ! Neighbours of node (i,j) in increasing node id order: Q1 the 3x3 block, P1 (diagonal
    ! lower-left to upper-right) the same without (i+1,j-1) and (i-1,j+1).
    if (mesh%element == ELEM_Q1) then
      nstencil = 9
      di(1:9) = [-1, 0, 1, -1, 0, 1, -1, 0, 1]
      dj(1:9) = [-1, -1, -1, 0, 0, 0, 1, 1, 1]
    else
      nstencil = 7
      di(1:7) = [-1, 0, -1, 0, 1, 0, 1]
      dj(1:7) = [-1, -1, 0, 0, 0, 1, 1]
    end if
    allocate (sys%colptr(n + 1))
    nnz = 0
    sys%colptr(1) = 0
    do p = 1, n
      k = (sys%dof_of(p) - 1)/2 + 1
      i = mod(k - 1, mesh%nx + 1)
      j = (k - 1)/(mesh%nx + 1)
      do s = 1, nstencil
        ii = i + di(s)
        jj = j + dj(s)
        if (ii < 0 .or. ii > mesh%nx .or. jj < 0 .or. jj > mesh%ny) cycle
        m = 1 + ii + jj*(mesh%nx + 1)
        do cc = 1, 2
          if (sys%free_of(2*(m - 1) + cc) > 0) nnz = nnz + 1
        end do
      end do
      if (nnz > int(huge(1), i8)) then
        info = 6
        write (msg, '(a,i0,a)') 'body ', body%id, ': the stiffness has more than 2^31-1 entries; '// &
          'the mesh is too large for 32-bit CSC indices'
        return
      end if
      sys%colptr(p + 1) = int(nnz)
    end do
    allocate (sys%rowind(nnz), sys%val(nnz))
    do p = 1, n
      k = (sys%dof_of(p) - 1)/2 + 1
      i = mod(k - 1, mesh%nx + 1)
      j = (k - 1)/(mesh%nx + 1)
      pos = sys%colptr(p)
      do s = 1, nstencil
        ii = i + di(s)
        jj = j + dj(s)
        if (ii < 0 .or. ii > mesh%nx .or. jj < 0 .or. jj > mesh%ny) cycle
        m = 1 + ii + jj*(mesh%nx + 1)
        do cc = 1, 2
          q = sys%free_of(2*(m - 1) + cc)
          if (q > 0) then
            pos = pos + 1
            sys%rowind(pos) = q - 1
          end if
        end do
      end do
    end do
    sys%val = 0.0_wp

    ! ---- loads ----------------------------------------------------------------------
    allocate (sys%f(n), sys%f_applied(ndof))
    sys%f = 0.0_wp
    sys%f_applied = 0.0_wp
    do t = 1, ntraction
      if (tractions(t)%body /= body%id) cycle
      call add_traction(mesh, tractions(t), sys%f_applied)
    end do
    if (present(body_force)) call add_body_force(mesh, body_force, sys%f_applied)

    ! ---- element loop: stiffness into CSC, lifting of prescribed values into f ----------
    cache%tol = 16.0_wp*epsilon(1.0_wp)*max(maxval(abs(mesh%xy)), tiny(1.0_wp))
    do c = 1, mesh%ncell
      do a = 1, nv
        xe(:, a) = mesh%xy(:, mesh%cells(a, c))
      end do
      call element_stiffness(mesh%element, xe, lam, mu, cache, ke, minjac)
      if (.not. (minjac > 0.0_wp)) then
        info = 7
        write (msg, '(a,i0,a,i0,a)') 'body ', body%id, ': cell ', c, &
          ' has a non-positive Jacobian (inverted or degenerate element)'
        return
      end if
      do a = 1, nv
        ldof(2*a - 1) = 2*(mesh%cells(a, c) - 1) + 1
        ldof(2*a) = 2*(mesh%cells(a, c) - 1) + 2
      end do
      ! Local dofs in increasing global (hence free) order, for the merge with the
      ! sorted rows of each column.
      do a = 1, nd
        perm(a) = a
      end do
      do a = 2, nd
        kk = perm(a)
        b = a - 1
        do while (b >= 1)
          if (ldof(perm(b)) <= ldof(kk)) exit
          perm(b + 1) = perm(b)
          b = b - 1
        end do
        perm(b + 1) = kk
      end do
      lift = .false.
      do a = 1, nd
        lfree(a) = sys%free_of(ldof(a))
        if (lfree(a) == 0) then
          ue(a) = sys%u_fixed(ldof(a))
          if (ue(a) /= 0.0_wp) lift = .true.
        else
          ue(a) = 0.0_wp
        end if
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
              info = 8
              write (msg, '(a,i0,a,i0,a)') 'body ', body%id, ': internal error, cell ', c, &
                ' couples DOFs outside the stiffness pattern'
              return
            end if
          end do
          sys%val(pos) = sys%val(pos) + ke(a, b)
        end do
      end do
      if (lift) then
        do a = 1, nd
          if (lfree(a) == 0) cycle
          sys%f(lfree(a)) = sys%f(lfree(a)) - dot_product(ke(a, 1:nd), ue(1:nd))
        end do
      end if
    end do

    do p = 1, n
      sys%f(p) = sys%f(p) + sys%f_applied(sys%dof_of(p))
    end do

    ! Infinity norm; the pattern is symmetric, so column sums are row sums.
    sys%k_norm = 0.0_wp
    do p = 1, n
      colsum = sum(abs(sys%val(sys%colptr(p) + 1:sys%colptr(p + 1))))
      sys%k_norm = max(sys%k_norm, colsum)
    end do
  end subroutine assemble_body

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
  subroutine residual_full(mesh, body, plane_strain, u_full, f_full, r)
    type(mesh_t), intent(in) :: mesh         !< the body's mesh
    type(body_cfg_t), intent(in) :: body     !< material
    logical, intent(in) :: plane_strain      !< .true. plane strain, .false. plane stress
    real(wp), intent(in) :: u_full(:)        !< (ndof) displacements [length]
    real(wp), intent(in) :: f_full(:)        !< (ndof) nodal loads [force]
    real(wp), intent(out) :: r(:)            !< (ndof) residual [force]
    integer :: c, a, nv, nd, ldof(8)
    real(wp) :: lam, mu, xe(2, 4), ke(8, 8), ue(8), minjac
    type(ke_cache_t) :: cache

    call lame_parameters(body, plane_strain, lam, mu)
    nv = mesh%nvert
    nd = 2*nv
    cache%tol = 16.0_wp*epsilon(1.0_wp)*max(maxval(abs(mesh%xy)), tiny(1.0_wp))
    r(1:2*mesh%nnode) = 0.0_wp
    do c = 1, mesh%ncell
      do a = 1, nv
        xe(:, a) = mesh%xy(:, mesh%cells(a, c))
        ldof(2*a - 1) = 2*(mesh%cells(a, c) - 1) + 1
        ldof(2*a) = 2*(mesh%cells(a, c) - 1) + 2
      end do
      call element_stiffness(mesh%element, xe, lam, mu, cache, ke, minjac)
      ue(1:nd) = u_full(ldof(1:nd))
      r(ldof(1:nd)) = r(ldof(1:nd)) + matmul(ke(1:nd, 1:nd), ue(1:nd))
    end do
    r(1:2*mesh%nnode) = r(1:2*mesh%nnode) - f_full(1:2*mesh%nnode)
  end subroutine residual_full

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
    integer :: c, a, k, nv
    integer, allocatable :: cnt(:)
    real(wp) :: lam, mu, xe(2, 4), g(2, 4), nfun(4), det, exx, eyy, gxy, cs(4)
    real(wp) :: sxx, syy, sxy, szz

    call lame_parameters(body, plane_strain, lam, mu)
    nv = mesh%nvert
    allocate (cnt(mesh%nnode))
    cnt = 0
    sigma(:, 1:mesh%nnode) = 0.0_wp
    do c = 1, mesh%ncell
      do a = 1, nv
        xe(:, a) = mesh%xy(:, mesh%cells(a, c))
      end do
      if (mesh%element == ELEM_Q1) then
        call q1_gradients(xe, 0.0_wp, 0.0_wp, nfun, g, det)
      else
        call p1_gradients(xe, g, det)
      end if
      exx = 0.0_wp
      eyy = 0.0_wp
      gxy = 0.0_wp
      do a = 1, nv
        k = mesh%cells(a, c)
        exx = exx + g(1, a)*u_full(2*k - 1)
        eyy = eyy + g(2, a)*u_full(2*k)
        gxy = gxy + g(2, a)*u_full(2*k - 1) + g(1, a)*u_full(2*k)
      end do
      cs(1) = (lam + 2.0_wp*mu)*exx + lam*eyy
      cs(2) = lam*exx + (lam + 2.0_wp*mu)*eyy
      cs(3) = mu*gxy
      if (plane_strain) then
        cs(4) = lam*(exx + eyy)    ! = nu (sxx + syy)
      else
        cs(4) = 0.0_wp
      end if
      do a = 1, nv
        k = mesh%cells(a, c)
        sigma(:, k) = sigma(:, k) + cs
        cnt(k) = cnt(k) + 1
      end do
    end do
    do k = 1, mesh%nnode
      if (cnt(k) > 0) sigma(:, k) = sigma(:, k)/real(cnt(k), wp)
      sxx = sigma(1, k)
      syy = sigma(2, k)
      sxy = sigma(3, k)
      szz = sigma(4, k)
      von_mises(k) = sqrt(0.5_wp*((sxx - syy)**2 + (syy - szz)**2 + (szz - sxx)**2) + 3.0_wp*sxy**2)
    end do
  end subroutine nodal_stress

  !> y = K x on the free DOFs (the pattern is symmetric: column j is row j).
  subroutine csc_matvec(sys, x, y)
    type(body_system_t), intent(in) :: sys   !< the body's system
    real(wp), intent(in) :: x(:)             !< (n) [length]
    real(wp), intent(out) :: y(:)            !< (n) [force]
    integer :: j, p
    real(wp) :: acc
    do j = 1, sys%n
      acc = 0.0_wp
      do p = sys%colptr(j) + 1, sys%colptr(j + 1)
        acc = acc + sys%val(p)*x(sys%rowind(p) + 1)
      end do
      y(j) = acc
    end do
  end subroutine csc_matvec

  ! ---------------------------------------------------------------------------------
  ! Element routines
  ! ---------------------------------------------------------------------------------

  !> Shape functions and their x, y gradients of the bilinear quadrilateral at (xi, eta).
  pure subroutine q1_gradients(xe, xi, eta, nfun, g, det)
    real(wp), intent(in) :: xe(2, 4)
    real(wp), intent(in) :: xi, eta
    real(wp), intent(out) :: nfun(4), g(2, 4), det
    real(wp) :: dxi(4), deta(4), j11, j12, j21, j22
    integer :: a
    do a = 1, 4
      nfun(a) = 0.25_wp*(1.0_wp + xi*xa_q1(a))*(1.0_wp + eta*ea_q1(a))
      dxi(a) = 0.25_wp*xa_q1(a)*(1.0_wp + eta*ea_q1(a))
      deta(a) = 0.25_wp*ea_q1(a)*(1.0_wp + xi*xa_q1(a))
    end do
    j11 = sum(dxi*xe(1, :))
    j12 = sum(dxi*xe(2, :))
    j21 = sum(deta*xe(1, :))
    j22 = sum(deta*xe(2, :))
    det = j11*j22 - j12*j21
    if (det > 0.0_wp) then
      do a = 1, 4
        g(1, a) = (j22*dxi(a) - j12*deta(a))/det
        g(2, a) = (-j21*dxi(a) + j11*deta(a))/det
      end do
    else
      g = 0.0_wp
    end if
  end subroutine q1_gradients

  !> Constant gradients of the linear triangle's shape functions; det = twice its area.
  pure subroutine p1_gradients(xe, g, det)
    real(wp), intent(in) :: xe(2, 4)
    real(wp), intent(out) :: g(2, 4), det
    det = (xe(1, 2) - xe(1, 1))*(xe(2, 3) - xe(2, 1)) - (xe(1, 3) - xe(1, 1))*(xe(2, 2) - xe(2, 1))
    g = 0.0_wp
    if (det > 0.0_wp) then
      g(1, 1) = (xe(2, 2) - xe(2, 3))/det
      g(2, 1) = (xe(1, 3) - xe(1, 2))/det
      g(1, 2) = (xe(2, 3) - xe(2, 1))/det
      g(2, 2) = (xe(1, 1) - xe(1, 3))/det
      g(1, 3) = (xe(2, 1) - xe(2, 2))/det
      g(2, 3) = (xe(1, 2) - xe(1, 1))/det
    end if
  end subroutine p1_gradients

  !> Add w * B^T D B to ke for the gradients g of nv shape functions (isotropic D).
  pure subroutine add_btdb(nv, g, w, lam, mu, ke)
    integer, intent(in) :: nv
    real(wp), intent(in) :: g(2, 4), w, lam, mu
    real(wp), intent(inout) :: ke(8, 8)
    integer :: a, b
    real(wp) :: c11, xa, ya, xb, yb
    c11 = lam + 2.0_wp*mu
    do b = 1, nv
      xb = g(1, b)*w
      yb = g(2, b)*w
      do a = 1, nv
        xa = g(1, a)
        ya = g(2, a)
        ke(2*a - 1, 2*b - 1) = ke(2*a - 1, 2*b - 1) + c11*xa*xb + mu*ya*yb
        ke(2*a, 2*b - 1) = ke(2*a, 2*b - 1) + lam*ya*xb + mu*xa*yb
        ke(2*a - 1, 2*b) = ke(2*a - 1, 2*b) + lam*xa*yb + mu*ya*xb
        ke(2*a, 2*b) = ke(2*a, 2*b) + c11*ya*yb + mu*xa*xb
      end do
    end do
  end subroutine add_btdb

  !> Element stiffness (Q1: 2x2 Gauss; P1: exact), reusing the cached one when the cell is
  !! a translate of the last computed cell. minjac: smallest Jacobian determinant seen.
  subroutine element_stiffness(element, xe, lam, mu, cache, ke, minjac)
    integer, intent(in) :: element
    real(wp), intent(in) :: xe(2, 4), lam, mu
    type(ke_cache_t), intent(inout) :: cache
    real(wp), intent(out) :: ke(8, 8), minjac
    real(wp), parameter :: gp = 0.577350269189625764509148780502_wp   ! 1/sqrt(3)
    real(wp) :: rel(2, 4), g(2, 4), nfun(4), det
    integer :: nv, a, ig, jg

    nv = 4
    if (element == ELEM_P1) nv = 3
    do a = 1, nv
      rel(:, a) = xe(:, a) - xe(:, 1)
    end do
    if (cache%valid) then
      if (all(abs(rel(:, 1:nv) - cache%rel(:, 1:nv)) <= cache%tol)) then
        ke = cache%ke
        minjac = cache%minjac
        return
      end if
    end if

    ke = 0.0_wp
    if (element == ELEM_Q1) then
      minjac = huge(1.0_wp)
      do jg = -1, 1, 2
        do ig = -1, 1, 2
          call q1_gradients(xe, ig*gp, jg*gp, nfun, g, det)
          minjac = min(minjac, det)
          if (det > 0.0_wp) call add_btdb(4, g, det, lam, mu, ke)   ! Gauss weights are 1
        end do
      end do
    else
      call p1_gradients(xe, g, det)
      minjac = det
      if (det > 0.0_wp) call add_btdb(3, g, 0.5_wp*det, lam, mu, ke)
    end if
    cache%valid = .true.
    cache%rel(:, 1:nv) = rel(:, 1:nv)
    cache%ke = ke
    cache%minjac = minjac
  end subroutine element_stiffness

  !> Consistent nodal loads of a linear traction on one side, 2-point Gauss per edge
  !! (exact for a linear traction times linear shape functions).
  subroutine add_traction(mesh, tr, f)
    type(mesh_t), intent(in) :: mesh
    type(traction_cfg_t), intent(in) :: tr
    real(wp), intent(inout) :: f(:)
    real(wp), parameter :: gp = 0.577350269189625764509148780502_wp
    integer, allocatable :: nodes(:)
    integer :: e, ig, na, nb, coord
    real(wp) :: xa(2), xb(2), len, xi, wa, wb, s, tv(2)

    call side_nodes(mesh, tr%side, nodes)
    coord = 1
    if (tr%side == SIDE_LEFT .or. tr%side == SIDE_RIGHT) coord = 2
    do e = 1, size(nodes) - 1
      na = nodes(e)
      nb = nodes(e + 1)
      xa = mesh%xy(:, na)
      xb = mesh%xy(:, nb)
      len = norm2(xb - xa)
      do ig = -1, 1, 2
        xi = ig*gp
        wa = 0.5_wp*(1.0_wp - xi)
        wb = 0.5_wp*(1.0_wp + xi)
        s = wa*xa(coord) + wb*xb(coord)
        tv = tr%t0 + tr%t1*s
        ! Gauss weight 1, Jacobian len/2.
        f(2*na - 1:2*na) = f(2*na - 1:2*na) + 0.5_wp*len*wa*tv
        f(2*nb - 1:2*nb) = f(2*nb - 1:2*nb) + 0.5_wp*len*wb*tv
      end do
    end do
  end subroutine add_traction

  !> Consistent nodal loads of a body force density: Q1 3x3 Gauss, P1 the 3-point
  !! interior rule of degree 2.
  subroutine add_body_force(mesh, bf, f)
    type(mesh_t), intent(in) :: mesh
    procedure(body_force_fn) :: bf
    real(wp), intent(inout) :: f(:)
    real(wp), parameter :: q3(3) = [-0.774596669241483377035853079956_wp, 0.0_wp, &
                                     0.774596669241483377035853079956_wp]
    real(wp), parameter :: w3(3) = [5.0_wp/9.0_wp, 8.0_wp/9.0_wp, 5.0_wp/9.0_wp]
    real(wp), parameter :: bary(3, 3) = reshape([2.0_wp/3.0_wp, 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 2.0_wp/3.0_wp, 1.0_wp/6.0_wp, &
                                                 1.0_wp/6.0_wp, 1.0_wp/6.0_wp, 2.0_wp/3.0_wp], [3, 3])
    integer :: c, a, k, ig, jg, nv
    real(wp) :: xe(2, 4), nfun(4), g(2, 4), det, xq(2), bv(2)

    nv = mesh%nvert
    do c = 1, mesh%ncell
      do a = 1, nv
        xe(:, a) = mesh%xy(:, mesh%cells(a, c))
      end do
      if (mesh%element == ELEM_Q1) then
        do jg = 1, 3
          do ig = 1, 3
            call q1_gradients(xe, q3(ig), q3(jg), nfun, g, det)
            xq = matmul(xe, nfun)
            call bf(xq(1), xq(2), bv)
            do a = 1, 4
              k = mesh%cells(a, c)
              f(2*k - 1:2*k) = f(2*k - 1:2*k) + w3(ig)*w3(jg)*det*nfun(a)*bv
            end do
          end do
        end do
      else
        call p1_gradients(xe, g, det)
        do ig = 1, 3
          xq = matmul(xe(:, 1:3), bary(:, ig))
          call bf(xq(1), xq(2), bv)
          do a = 1, 3
            k = mesh%cells(a, c)
            ! weight area/3 = det/6
            f(2*k - 1:2*k) = f(2*k - 1:2*k) + (det/6.0_wp)*bary(a, ig)*bv
          end do
        end do
      end if
    end do
  end subroutine add_body_force

end module assembly
