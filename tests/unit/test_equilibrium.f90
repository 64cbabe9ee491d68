!> Global equilibrium of the seed's upper body (doc/performance.md, "The paper's Table 1") solved alone, its contact side
!! left free: the applied loads have the right resultant, and the reactions at the
!! clamped side balance them in force and moment; the same scene in mm, N, MPa gives
!! the same displacements. Q1 and P1, plane strain and plane stress. Solves use LAPACK's
!! banded Cholesky (testing's band_solve).
program test_equilibrium
  use kinds, only: wp
  use config, only: body_cfg_t, traction_cfg_t, ELEM_Q1, ELEM_P1, element_names, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, BC_FREE, BC_CLAMPED, BC_CONTACT
  use mesh, only: mesh_t
  use assembly, only: body_system_t, assemble_body, residual_full
  use testing, only: grid_mesh, grid_mesh_parts, report, test_summary, solve_full, error_parts
  use errors, only: error_t
  implicit none (type, external)

  real(wp), parameter :: load_y = -11.5e6_wp   ! total applied vertical load [N/m]

  call scene(ELEM_Q1, .true.)
  call scene(ELEM_P1, .true.)
  call scene(ELEM_Q1, .false.)
  call scene(ELEM_P1, .false.)
  call dof_counts()

  call test_summary()

contains

  !> The seed's body 1 in SI units (scale = 1) or in mm, N, MPa (scale = 1e3 mm per m).
  subroutine seed_body(element, nx, ny, to_mm, body, tr)
    integer, intent(in) :: element, nx, ny
    logical, intent(in) :: to_mm
    type(body_cfg_t), intent(out) :: body
    type(traction_cfg_t), intent(out) :: tr(2)
    real(wp) :: ls, ss   ! length and stress scales
    ls = merge(1.0e3_wp, 1.0_wp, to_mm)
    ss = merge(1.0e-6_wp, 1.0_wp, to_mm)
    body%id = 1
    body%x0 = 0.0_wp
    body%y0 = 1.0_wp*ls
    body%width = 3.0_wp*ls
    body%height = 1.0_wp*ls
    body%nx = nx
    body%ny = ny
    body%element = element
    body%young = 2.1e11_wp*ss
    body%poisson = 0.277_wp
    body%bc = BC_FREE
    body%bc(SIDE_LEFT) = BC_CLAMPED
    body%bc(SIDE_BOTTOM) = BC_CONTACT          ! contact side: no condition when alone
    tr(1)%body = 1
    tr(1)%side = SIDE_TOP
    tr(1)%t0(1:2) = [0.0_wp, -3.0e6_wp]*ss
    tr(1)%t1(1:2) = [0.0_wp, -1.0e6_wp]*ss/ls
    tr(2)%body = 1
    tr(2)%side = SIDE_RIGHT
    tr(2)%t0(1:2) = [0.0_wp, 2.0e6_wp]*ss
    tr(2)%t1 = 0.0_wp
  end subroutine seed_body

  subroutine solve(body, tr, plane_strain, m, sys, u)
    type(body_cfg_t), intent(in) :: body
    type(traction_cfg_t), intent(in) :: tr(:)
    logical, intent(in) :: plane_strain
    type(mesh_t), intent(out) :: m
    type(body_system_t), intent(out) :: sys
    real(wp), allocatable, intent(out) :: u(:)
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    call grid_mesh_parts(m, body, info, msg)
    if (info == 0) then
      call assemble_body(m, body, plane_strain, tr, size(tr), sys, err)
      call error_parts(err, info, msg)
    end if
    call solve_full(sys, info, msg, 'mesh/assembly', u)
  end subroutine solve

  subroutine scene(element, plane_strain)
    integer, intent(in) :: element
    logical, intent(in) :: plane_strain
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(2)
    type(mesh_t) :: m
    type(body_system_t) :: sys
    real(wp), allocatable :: u(:), u_mm(:), r(:)
    real(wp) :: fsum(2), rsum(2), rfree, mom_load, mom_react, err, scale
    integer :: k
    character(len=24) :: tag

    tag = element_names(element)//' '//merge('plane strain', 'plane stress', plane_strain)//':'
    call seed_body(element, 24, 16, .false., body, tr)
    call solve(body, tr, plane_strain, m, sys, u)

    fsum = [sum(sys%f_applied(1::2)), sum(sys%f_applied(2::2))]
    call report(abs(fsum(2) - load_y) <= 1.0e-12_wp*abs(load_y), &
                trim(tag)//' applied load y = -11.5e6 N/m (rel err)', &
                abs(fsum(2) - load_y)/abs(load_y), 1.0e-12_wp)
    call report(abs(fsum(1)) <= 1.0e-12_wp*abs(load_y), &
                trim(tag)//' applied load x = 0 (rel)', abs(fsum(1))/abs(load_y), 1.0e-12_wp)

    ! Reactions: r = K_full u - f_full, non-zero only at the clamped DOFs.
    allocate (r(sys%ndof))
    call residual_full(m, body, plane_strain, u, sys%f_applied, r)
    rsum = 0.0_wp
    rfree = 0.0_wp
    mom_load = 0.0_wp
    mom_react = 0.0_wp
    do k = 1, m%nnode
      mom_load = mom_load + m%xy(1, k)*sys%f_applied(2*k) - m%xy(2, k)*sys%f_applied(2*k - 1)
      if (sys%free_of(2*k - 1) == 0) then
        rsum(1) = rsum(1) + r(2*k - 1)
        mom_react = mom_react - m%xy(2, k)*r(2*k - 1)
      else
        rfree = max(rfree, abs(r(2*k - 1)))
      end if
      if (sys%free_of(2*k) == 0) then
        rsum(2) = rsum(2) + r(2*k)
        mom_react = mom_react + m%xy(1, k)*r(2*k)
      else
        rfree = max(rfree, abs(r(2*k)))
      end if
    end do
    call report(rfree <= 1.0e-10_wp*abs(load_y), &
                trim(tag)//' residual at free DOFs ~ 0 (max |r|/|F|)', rfree/abs(load_y), 1.0e-10_wp)
    call report(abs(rsum(1) + fsum(1)) <= 1.0e-10_wp*abs(load_y), &
                trim(tag)//' reactions + loads = 0 in x (rel)', &
                abs(rsum(1) + fsum(1))/abs(load_y), 1.0e-10_wp)
    call report(abs(rsum(2) + fsum(2)) <= 1.0e-10_wp*abs(load_y), &
                trim(tag)//' reactions + loads = 0 in y (rel)', &
                abs(rsum(2) + fsum(2))/abs(load_y), 1.0e-10_wp)
    ! Moments about the origin; the lever arm scale is the body's size (3 m).
    call report(abs(mom_react + mom_load) <= 1.0e-10_wp*abs(mom_load), &
                trim(tag)//' reaction moment + load moment = 0 (rel)', &
                abs(mom_react + mom_load)/abs(mom_load), 1.0e-10_wp)
    ! The same scene in mm, N, MPa.
    call seed_body(element, 24, 16, .true., body, tr)
    call solve(body, tr, plane_strain, m, sys, u_mm)
    scale = maxval(abs(u_mm))
    err = maxval(abs(u_mm - 1.0e3_wp*u))
    call report(err <= 1.0e-10_wp*scale, &
                trim(tag)//' mm/N/MPa displacements = 1e3 x SI (max rel err)', err/scale, 1.0e-10_wp)
    call report(abs(sum(sys%f_applied(2::2)) - load_y*1.0e-3_wp) <= 1.0e-12_wp*abs(load_y)*1.0e-3_wp, &
                trim(tag)//' mm/N/MPa applied load y = -11.5e3 N/mm (rel)', &
                abs(sum(sys%f_applied(2::2)) - load_y*1.0e-3_wp)/(abs(load_y)*1.0e-3_wp), 1.0e-12_wp)
  end subroutine scene

  !> The seed's Table 1 DOF counts of one body (n) for its four meshes, left side clamped.
  subroutine dof_counts()
    integer, parameter :: nxs(4) = [3, 6, 16, 24], nys(4) = [1, 2, 8, 16], nexp(4) = [12, 36, 288, 816]
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: tr(2)
    type(mesh_t) :: m
    type(body_system_t) :: sys
    integer :: i, info
    type(error_t) :: err
    character(len=256) :: msg
    character(len=64) :: what
    do i = 1, 4
      call seed_body(ELEM_Q1, nxs(i), nys(i), .false., body, tr)
      call grid_mesh(m, body)
      call assemble_body(m, body, .true., tr, 2, sys, err)
      call error_parts(err, info, msg)
      write (what, '(a,i0,a,i0,a,i0,a)') 'seed mesh ', nxs(i), 'x', nys(i), ': n = ', nexp(i), ' free DOFs'
      call report(info == 0 .and. sys%n == nexp(i), trim(what), real(sys%n, wp), real(nexp(i), wp))
    end do
  end subroutine dof_counts

end program test_equilibrium
