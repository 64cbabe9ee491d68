!> Reading and assembly of a deck's bodies on one thread, timed apart (prints, asserts
!! nothing): the bodies' meshes (the Gmsh reader, a file shared by bodies parsed once;
!! or the structured grid), then assemble_body of each body, the stiffness included.
!! CPU time and wall time of each step, the fastest of `repeat` rounds; the CPU time
!! holds on a shared machine, where the wall time does not.
!!
!! Usage: bench_assembly_rate DECK.nml [OVERRIDE ...]   (BENCH_REPEAT rounds, default 3)
!! Prints one line: free DOFs (all bodies), read and assemble [s] CPU and wall, and the
!! CPU microseconds per free DOF of each.
program bench_assembly_rate
  use kinds, only: wp
  use config, only: deck_t
  use deck, only: read_deck
  use mesh, only: mesh_t, mesh_build
  use gmsh_msh, only: msh_read_shared
  use assembly, only: assemble_body, body_system_t
  use errors, only: error_t
  use clock, only: wtime
  implicit none (type, external)
  character(len=512) :: path, arg
  character(len=512), allocatable :: overrides(:)
  type(deck_t) :: d
  type(mesh_t), allocatable :: m(:)
  type(body_system_t), allocatable :: s(:)
  type(error_t), allocatable :: e(:)
  type(error_t) :: e1
  real(wp) :: w(3), best_w(2)
  real :: t(3), best_t(2)
  integer :: a, rep, nrep, ndof, stat

  call get_command_argument(1, path)
  allocate (overrides(max(0, command_argument_count() - 1)))
  do a = 2, command_argument_count()
    call get_command_argument(a, overrides(a - 1))
  end do
  nrep = 3
  call get_environment_variable('BENCH_REPEAT', arg)
  if (len_trim(arg) > 0) read (arg, *, iostat=stat) nrep
  call read_deck(trim(path), overrides, d, e1)
  if (e1%failed()) error stop 'bad deck: '//e1%message
  best_t = huge(1.0)
  best_w = huge(1.0_wp)
  do rep = 1, max(1, nrep)
    allocate (m(d%nbody), s(d%nbody), e(d%nbody))
    call cpu_time(t(1))
    w(1) = wtime()
    if (len_trim(d%body(1)%mesh) > 0) then
      call msh_read_shared(trim(d%body(1)%mesh), [(d%body(a)%region, a=1, d%nbody)], [(a, a=1, d%nbody)], m, e, 1)
    else
      do a = 1, d%nbody
        call mesh_build(m(a), d%body(a), e(a))
      end do
    end if
    call cpu_time(t(2))
    w(2) = wtime()
    do a = 1, d%nbody
      if (.not. e(a)%failed()) call assemble_body(m(a), d%body(a), d%plane_strain, d%traction, d%ntraction, s(a), &
                                                  e(a), boundaries=d%boundary(1:d%nboundary))
      if (e(a)%failed()) error stop 'bench_assembly_rate: '//e(a)%text()
    end do
    call cpu_time(t(3))
    w(3) = wtime()
    best_t = min(best_t, t(2:3) - t(1:2))
    best_w = min(best_w, w(2:3) - w(1:2))
    ndof = sum(s(:)%n)
    deallocate (m, s, e)
  end do
  write (*, '(a,i0,4(a,f0.4),2(a,f0.3))') 'dofs=', ndof, ' read_cpu=', best_t(1), ' assemble_cpu=', best_t(2), &
    ' read_wall=', best_w(1), ' assemble_wall=', best_w(2), ' read_us_per_dof=', 1.0e6*best_t(1)/ndof, &
    ' assemble_us_per_dof=', 1.0e6*best_t(2)/ndof
end program bench_assembly_rate
