!> Load steps and stages (`&solver load_steps`, `stage=` of the load groups): the steps of
!! a run, each step's loads, its interface load re-condensed on the existing factor, and the
!! history one step hands the next.
!!
!! Stage s ramps its loads from 0 to their full value over its N_s steps while the earlier
!! stages' are held: step k of stage s applies sum_{r<s} L_r + (k/N_s) L_s. The load vectors
!! are linear in the loads, so a step's f, u_fixed and f_applied are that combination of the
!! stages' columns (assembly%stage_loads), and its b_a = B_a K_a^-1 f_a + B_a,d u_d is one
!! solve per body with the factor the run already has.
module load_history
  use kinds, only: wp
  use config, only: deck_t, stage_count, stage_steps
  use assembly, only: body_system_t
  use contact_interface, only: interface_t
  use condense, only: body_condensed_t, interface_load, prescribed_part
  use floating, only: rigid_rows
  use errors, only: error_t
  implicit none (type, external)
  private

  !> One load step: its stage, its place in the stage and its load factor k/N_s.
  type, public :: load_step_t
    integer :: stage = 1              !< the stage it ramps
    integer :: index = 1              !< k: the step of the stage, 1..N_s
    real(wp) :: factor = 1.0_wp       !< k/N_s, of the stage's loads [-]
  end type load_step_t

  !> What a converged step hands the next, in the interface's side layout (m, 2): its
  !! contact forces, normal interface displacements (B u of each side) and obstacles. A
  !! frictional step needs the first two for its slip increment; a frictionless one is
  !! independent of the step before, and the obstacles and forces only warm-start it.
  type, public :: step_history_t
    integer :: step = 0                        !< the step they are from (0: none yet)
    real(wp), allocatable :: lam(:, :)         !< (m,2) converged contact force of each side [force]
    real(wp), allocatable :: w(:, :)           !< (m,2) normal interface displacement of each side [length]
    real(wp), allocatable :: obstacle(:, :)    !< (m,2) final obstacles of each side [length]
  end type step_history_t

  public :: plan_steps, set_step_loads, step_interface_load

contains

  !> The steps of the deck, stage by stage: N_s = its load_steps for stage s.
  function plan_steps(d) result(steps)
    type(deck_t), intent(in) :: d               !< the effective deck
    type(load_step_t), allocatable :: steps(:)
    integer, allocatable :: n(:)
    integer :: s, j, k
    allocate (n(stage_count(d)))
    n = stage_steps(d%solver, size(n))
    allocate (steps(sum(n)))
    k = 0
    do s = 1, size(n)
      do j = 1, n(s)
        k = k + 1
        steps(k) = load_step_t(s, j, real(j, wp)/real(n(s), wp))
      end do
    end do
  end function plan_steps

  !> The body's load of one step: f, u_fixed and f_applied from the stages' columns, the
  !! earlier stages whole, the step's own scaled by its factor.
  subroutine set_step_loads(sys, step)
    type(body_system_t), intent(inout) :: sys   !< its stage columns; gets f, u_fixed, f_applied
    type(load_step_t), intent(in) :: step       !< the step
    call combine(sys%f_stage, sys%f)
    call combine(sys%u_stage, sys%u_fixed)
    call combine(sys%fa_stage, sys%f_applied)
  contains
    subroutine combine(cols, x)
      real(wp), intent(in) :: cols(:, :)
      real(wp), intent(inout) :: x(:)
      integer :: r
      x = 0.0_wp
      do r = 1, step%stage - 1
        x = x + cols(:, r)
      end do
      x = x + step%factor*cols(:, step%stage)
    end subroutine combine
  end subroutine set_step_loads

  !> The body's interface load for its current loads, on its factor (on one rank: CHOLMOD or banded):
  !! u0 = K_a^-1 f_a and b_a = B_a u0 + B_a,d u_d; for a body held only by contact its
  !! load along the free motions too (floating%rigid_rows). One solve, no factorization.
  subroutine step_interface_load(itf, a, sys, cbody, err)
    type(interface_t), intent(in) :: itf           !< the contact rows of all pairs
    integer, intent(in) :: a                       !< the body
    type(body_system_t), intent(in) :: sys         !< its loads of the step
    type(body_condensed_t), intent(inout) :: cbody !< its factor; gets bfix, u0, b (and re)
    type(error_t), intent(out) :: err              !< the solve's failure, if any
    call prescribed_part(itf, sys, cbody)
    call interface_load(sys, cbody, err)
    if (err%failed()) return
    if (sys%nrig > 0) call rigid_rows(itf, a, sys, cbody)
  end subroutine step_interface_load

end module load_history
