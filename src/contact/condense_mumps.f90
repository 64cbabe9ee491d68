!> Interface condensation of one body through MUMPS (doc/batch.md, "MPI and MUMPS"), the
!! distributed counterpart of condense%factor_body/condense_body: the body's interface
!! DOFs (condense%interface_dofs) are MUMPS's Schur variables, X = S^-1 = (K_a^-1) on them
!! gives F_a = B_a X B_a' (condense%flex_from_x), b_a = B_a K_a^-1 f_a comes from a MUMPS
!! solve, and so does the displacement under the contact forces. Every routine is
!! collective over the body's group of ranks; the results (flex, b, u) are on its host.
module condense_mumps
  use kinds, only: wp
  use clock, only: wtime
  use assembly, only: body_system_t
  use contact_interface, only: interface_t
  use condense, only: body_condensed_t, interface_dofs, flex_from_x, apply_b, apply_bt
  use mumps_iface, only: mumps_t, mumps_schur_factor, mumps_solve
  use errors, only: error_t
  implicit none (type, external)
  private

  public :: factor_body_mumps, condense_body_mumps, recover_displacement_mumps

contains

  !> Analyse and factorize K_a over the group with the interface DOFs as Schur variables;
  !! on the host, X = S^-1. err: MUMPS failed or K_a singular (which and why).
  subroutine factor_body_mumps(itf, a, sys, irn, jcn, val, comm, bc, mt, err)
    type(interface_t), intent(in) :: itf             !< the contact line
    integer, intent(in) :: a                         !< body number
    type(body_system_t), intent(in) :: sys           !< body a's DOF numbering and load
    integer, intent(in) :: irn(:), jcn(:)            !< this rank's share of K_a (assembly%cell_triplets)
    real(wp), intent(in) :: val(:)                   !< its entries [stress]
    integer, intent(in) :: comm                      !< the body's group of ranks
    type(body_condensed_t), intent(inout) :: bc      !< receives the interface DOFs and rows
    type(mumps_t), intent(inout) :: mt               !< receives the MUMPS instance
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp) :: t0
    t0 = wtime()
    call interface_dofs(itf, a, sys, bc)
    call mumps_schur_factor(mt, comm, sys%n, irn, jcn, val, bc%idx, a, err)
    bc%t_factor = wtime() - t0
  end subroutine factor_body_mumps

  !> F_a from X (host) and b_a = B_a K_a^-1 f_a by a MUMPS solve (collective).
  subroutine condense_body_mumps(sys, bc, mt, a, err)
    type(body_system_t), intent(in) :: sys           !< assembled system of the body
    type(body_condensed_t), intent(inout) :: bc      !< receives flex, b (host)
    type(mumps_t), intent(inout) :: mt               !< the factorized body
    integer, intent(in) :: a                         !< body number
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp), allocatable :: u0(:)
    real(wp) :: t0
    t0 = wtime()
    if (allocated(bc%b)) deallocate (bc%b)
    allocate (bc%b(bc%m))
    if (mt%host) then
      call flex_from_x(bc, mt%x)
      u0 = sys%f
    else
      allocate (u0(0))
    end if
    call mumps_solve(mt, u0, a, err)
    if (.not. err%failed() .and. mt%host) call apply_b(bc, u0, bc%b)
    bc%t_condense = wtime() - t0
  end subroutine condense_body_mumps

  !> u_free = K_a^-1 (f_a - B_a' lam) by a MUMPS solve (collective; u_free on the host).
  subroutine recover_displacement_mumps(sys, bc, mt, a, lam, u_free, err)
    type(body_system_t), intent(in) :: sys           !< assembled system
    type(body_condensed_t), intent(in) :: bc         !< condensed body (its rows)
    type(mumps_t), intent(inout) :: mt               !< the factorized body
    integer, intent(in) :: a                         !< body number
    real(wp), intent(in) :: lam(:)                   !< (m) contact force on this body [force]
    real(wp), intent(out) :: u_free(:)               !< (n) host: displacement at free DOFs [length]
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp), allocatable :: r(:)
    if (mt%host) then
      r = sys%f
      r = -r
      call apply_bt(bc, lam, r)
      r = -r
    else
      allocate (r(0))
    end if
    call mumps_solve(mt, r, a, err)
    if (mt%host .and. .not. err%failed()) u_free = r
  end subroutine recover_displacement_mumps

end module condense_mumps
