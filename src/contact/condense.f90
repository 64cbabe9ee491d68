!> Interface condensation: the contact line shared by the two bodies, and for each
!! body its factorization, normal flexibility F_a = B_a K_a^-1 B_a' and the normal
!! interface displacement under the load alone b_a = B_a K_a^-1 f_a (README, "Method as implemented").
!! The interface DOFs are ordered last in the Cholesky factorization, so F_a comes
!! from the trailing block of the factor at a cost of O(m^3), not m solves.
module condense
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use config, only: body_cfg_t, contact_cfg_t, factor_cfg_t, BC_CONTACT, SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, &
                    SIDE_TOP, FACTOR_BANDED, ORDER_AMD, ORDER_NATURAL, ORDER_ND
  use mesh, only: mesh_t, side_nodes
  use assembly, only: body_system_t
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN
  use ordering, only: nested_dissection
  use clock, only: wtime
  implicit none (type, external)
  private

  !> The contact line: m node pairs where both bodies' normal displacement is free.
  type, public :: interface_t
    integer :: m = 0                        !< contact node pairs
    integer :: side(2) = 0                  !< contact side of each body (SIDE_*)
    integer :: axis = 1                     !< coordinate along the line: 1 = x, 2 = y
    real(wp), allocatable :: s(:)           !< (m) coordinate along the line [length]
    real(wp), allocatable :: xy(:, :)       !< (2,m) node coordinates [length]
    real(wp), allocatable :: g0(:)          !< (m) initial normal gap [length]
    real(wp), allocatable :: trib(:)        !< (m) tributary length [length]
    integer, allocatable :: node(:, :)      !< (m,2) mesh node of each body
  end type interface_t

  !> One body reduced to the interface.
  type, public :: body_condensed_t
    integer :: m = 0                        !< interface size
    integer :: n = 0                        !< free DOFs of the body
    real(wp) :: normal(2) = 0.0_wp          !< outward normal of the contact side
    integer, allocatable :: idx(:)          !< (m) free DOF of the normal component
    real(wp), allocatable :: sgn(:)         !< (m) normal component of the outward normal (+-1)
    real(wp), allocatable :: flex(:, :)     !< (m,m) F_a [length/force]
    real(wp), allocatable :: b(:)           !< (m) B_a K_a^-1 f_a [length]
    real(wp), allocatable :: u0(:)          !< (n) K_a^-1 f_a [length]
    type(chol_t) :: chol                    !< the factorization of K_a
    real(wp) :: t_factor = 0.0_wp           !< wall time of analyze + factorize [s]
    real(wp) :: t_condense = 0.0_wp         !< wall time of F_a and b_a [s]
  end type body_condensed_t

  public :: build_interface, factor_body, condense_body, recover_displacement, apply_bt

contains

  !> Find the contact line and pair the nodes of the two bodies.
  !! info /= 0 with msg when the contact sides do not match node for node.
  subroutine build_interface(body, cc, msh, sys, itf, info, msg)
    type(body_cfg_t), intent(in) :: body(2)          !< the two bodies (their contact sides)
    type(contact_cfg_t), intent(in) :: cc            !< the interface settings (initial gap)
    type(mesh_t), intent(in) :: msh(2)               !< meshes of body 1 and 2
    type(body_system_t), intent(in) :: sys(2)        !< assembled systems
    type(interface_t), intent(out) :: itf            !< the contact line
    integer, intent(out) :: info                     !< 0 ok, 1 bad input
    character(len=*), intent(out) :: msg             !< description of a failure
    integer, allocatable :: nodes1(:), nodes2(:)
    integer :: a, k, i, c, d1, d2, nline
    logical, allocatable :: keep(:)
    real(wp), allocatable :: sl(:), tl(:)
    real(wp) :: scale, x1(2), x2(2)

    info = 0
    msg = ''
    do a = 1, 2
      itf%side(a) = 0
      do k = 1, 4
        if (body(a)%bc(k) == BC_CONTACT) itf%side(a) = k
      end do
      if (itf%side(a) == 0) then
        info = 1
        write (msg, '(a,i0,a)') 'body ', a, ' has no contact side'
        return
      end if
    end do
    call side_nodes(msh(1), itf%side(1), nodes1)
    call side_nodes(msh(2), itf%side(2), nodes2)
    if (size(nodes1) /= size(nodes2)) then
      info = 1
      write (msg, '(a,i0,a,i0,a)') 'contact sides do not match node for node (', size(nodes1), &
        ' nodes on body 1, ', size(nodes2), ' on body 2)'
      return
    end if
    nline = size(nodes1)
    if (itf%side(1) == SIDE_BOTTOM .or. itf%side(1) == SIDE_TOP) then
      itf%axis = 1; c = 2
    else
      itf%axis = 2; c = 1
    end if
    scale = max(body(1)%width, body(1)%height, body(2)%width, body(2)%height)
    allocate (keep(nline), sl(nline), tl(nline))
    do i = 1, nline
      x1 = msh(1)%xy(:, nodes1(i))
      x2 = msh(2)%xy(:, nodes2(i))
      if (maxval(abs(x1 - x2)) > 1.0e-9_wp*scale) then
        info = 1
        write (msg, '(a,i0,a,2es12.4,a,2es12.4,a)') 'contact sides do not match node for node: node ', i, &
          ' of the contact line is at (', x1, ') in body 1 and (', x2, ') in body 2'
        return
      end if
      sl(i) = x1(itf%axis)
      d1 = sys(1)%free_of(2*(nodes1(i) - 1) + c)
      d2 = sys(2)%free_of(2*(nodes2(i) - 1) + c)
      if ((d1 > 0) .neqv. (d2 > 0)) then
        info = 1
        write (msg, '(a,es12.4,a,i0,a)') 'contact node at s = ', sl(i), &
          ': its normal displacement is prescribed in body ', merge(1, 2, d1 == 0), &
          ' but free in the other; prescribe it in both or in neither'
        return
      end if
      keep(i) = d1 > 0
    end do
    ! tributary length along the whole line
    do i = 1, nline
      tl(i) = 0.0_wp
      if (i > 1) tl(i) = tl(i) + 0.5_wp*(sl(i) - sl(i - 1))
      if (i < nline) tl(i) = tl(i) + 0.5_wp*(sl(i + 1) - sl(i))
    end do
    itf%m = count(keep)
    allocate (itf%s(itf%m), itf%xy(2, itf%m), itf%g0(itf%m), itf%trib(itf%m), itf%node(itf%m, 2))
    k = 0
    do i = 1, nline
      if (.not. keep(i)) cycle
      k = k + 1
      itf%s(k) = sl(i)
      itf%xy(:, k) = msh(1)%xy(:, nodes1(i))
      itf%trib(k) = tl(i)
      itf%node(k, 1) = nodes1(i)
      itf%node(k, 2) = nodes2(i)
      if (cc%gap_radius > 0.0_wp) then
        itf%g0(k) = (sl(i) - cc%gap_center)**2/(2.0_wp*cc%gap_radius)
      else
        itf%g0(k) = 0.0_wp
      end if
    end do
  end subroutine build_interface

  !> Normal DOF indices and signs of body a on the interface.
  subroutine interface_dofs(itf, a, sys, bc)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a
    type(body_system_t), intent(in) :: sys
    type(body_condensed_t), intent(inout) :: bc
    integer :: i, c
    select case (itf%side(a))
    case (SIDE_LEFT)
      bc%normal = [-1.0_wp, 0.0_wp]
    case (SIDE_RIGHT)
      bc%normal = [1.0_wp, 0.0_wp]
    case (SIDE_BOTTOM)
      bc%normal = [0.0_wp, -1.0_wp]
    case default
      bc%normal = [0.0_wp, 1.0_wp]
    end select
    c = merge(2, 1, itf%axis == 1)
    bc%m = itf%m
    bc%n = sys%n
    if (allocated(bc%idx)) deallocate (bc%idx, bc%sgn)
    allocate (bc%idx(itf%m), bc%sgn(itf%m))
    do i = 1, itf%m
      bc%idx(i) = sys%free_of(2*(itf%node(i, a) - 1) + c)
      bc%sgn(i) = bc%normal(c)
    end do
  end subroutine interface_dofs

  !> Factorize K_a with the interface DOFs ordered last. ordering='nd' orders the
  !! other DOFs by geometric nested dissection of the body's grid (module ordering);
  !! its time is part of t_factor.
  subroutine factor_body(fc, itf, a, msh, sys, bc, info, msg)
    type(factor_cfg_t), intent(in) :: fc             !< factorization and ordering
    type(interface_t), intent(in) :: itf             !< the contact line
    integer, intent(in) :: a                         !< body number
    type(mesh_t), intent(in) :: msh                  !< mesh of body a
    type(body_system_t), intent(in) :: sys           !< assembled system of body a
    type(body_condensed_t), intent(inout) :: bc      !< receives the factorization
    integer, intent(out) :: info                     !< 0 ok, else failure (see chol_factor)
    character(len=*), intent(out) :: msg             !< description of a failure
    integer :: method, iord
    integer, allocatable :: perm(:)
    real(wp) :: t0

    t0 = wtime()
    call interface_dofs(itf, a, sys, bc)
    ! the deck's choice as the Cholesky module's method and ordering ('nd' is our own
    ! permutation of the interior, given to CHOLMOD)
    method = merge(FACT_BANDED, FACT_CHOLMOD, fc%factorization == FACTOR_BANDED)
    select case (fc%ordering)
    case (ORDER_AMD)
      iord = ORD_AMD
    case (ORDER_NATURAL)
      iord = ORD_NATURAL
    case (ORDER_ND)
      iord = ORD_GIVEN
    case default
      iord = ORD_METIS
    end select
    if (iord == ORD_GIVEN .and. method == FACT_CHOLMOD) then
      call nested_dissection(msh, sys, bc%idx, perm, info, msg)
      if (info /= 0) then
        bc%t_factor = wtime() - t0
        return
      end if
      call bc%chol%factor(sys%n, sys%colptr, sys%rowind, sys%val, method, iord, info, msg, last=bc%idx, &
                          interior_perm=perm)
    else
      call bc%chol%factor(sys%n, sys%colptr, sys%rowind, sys%val, method, iord, info, msg, last=bc%idx)
    end if
    bc%t_factor = wtime() - t0
  end subroutine factor_body

  !> Form F_a and b_a (and u0 = K_a^-1 f_a) from the factorization.
  subroutine condense_body(sys, bc, info, msg)
    type(body_system_t), intent(in) :: sys           !< assembled system of the body
    type(body_condensed_t), intent(inout) :: bc      !< factorized body; receives flex, b, u0
    integer, intent(out) :: info                     !< 0 ok
    character(len=*), intent(out) :: msg             !< description of a failure
    real(wp) :: t0
    integer :: i
    t0 = wtime()
    if (allocated(bc%flex)) deallocate (bc%flex)
    if (allocated(bc%b)) deallocate (bc%b)
    if (allocated(bc%u0)) deallocate (bc%u0)
    allocate (bc%flex(bc%m, bc%m), bc%b(bc%m), bc%u0(sys%n))
    info = 0
    msg = ''
    if (bc%m > 0) then
      call bc%chol%flexibility(bc%idx, bc%sgn, bc%flex, info, msg)
      if (info /= 0) return
    end if
    bc%u0 = sys%f
    call bc%chol%solve(bc%u0, info, msg)
    if (info /= 0) return
    do i = 1, bc%m
      bc%b(i) = bc%sgn(i)*bc%u0(bc%idx(i))
    end do
    bc%t_condense = wtime() - t0
  end subroutine condense_body

  !> r(n) = B_a' lam: scatter the interface forces onto the normal DOFs.
  subroutine apply_bt(bc, lam, r)
    type(body_condensed_t), intent(in) :: bc         !< condensed body
    real(wp), intent(in) :: lam(:)                   !< (m) interface forces [force]
    real(wp), intent(inout) :: r(:)                  !< (n) r += B_a' lam
    integer :: i
    do i = 1, bc%m
      r(bc%idx(i)) = r(bc%idx(i)) + bc%sgn(i)*lam(i)
    end do
  end subroutine apply_bt

  !> u_free = K_a^-1 (f_a - B_a' lam): the body's displacement under its load and
  !! the contact forces lam (one solve).
  subroutine recover_displacement(sys, bc, lam, u_free)
    type(body_system_t), intent(in) :: sys           !< assembled system
    type(body_condensed_t), intent(inout) :: bc      !< factorized body
    real(wp), intent(in) :: lam(:)                   !< (m) contact force on this body [force]
    real(wp), intent(out) :: u_free(:)               !< (n) displacement at free DOFs [length]
    real(wp), allocatable :: r(:)
    integer :: info
    allocate (r(sys%n))
    r = 0.0_wp
    call apply_bt(bc, lam, r)
    call bc%chol%solve(r, info)
    if (info /= 0) r = ieee_value(1.0_wp, ieee_quiet_nan)
    u_free = bc%u0 - r
  end subroutine recover_displacement

end module condense
