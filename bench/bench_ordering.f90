!> Benchmark of the fill-reducing orderings of one body (prints, asserts nothing).
!!
!! The paper's upper body (3 x 1, Q1, plane strain, clamped on the left, the contact DOFs
!! of the bottom side ordered last) at nx x ny cells, as a structured mesh and as a
!! general one (module testing's general_body: nodes renumbered at random, interior
!! nodes moved by up to 0.3 cells, structured = .false.), factored by CHOLMOD with
!! METIS, AMD (CAMD with the interface last) and our nested dissection ('nd': grid lines
!! on the structured mesh, coordinate bisection on the general one). One thread (the
!! shim holds OpenBLAS to one).
!!
!! Columns: mesh, kind, ordering, n, m, order = our ordering's own time (nd only; METIS
!! and AMD run inside analyze), analyze (ordering + symbolic), factor (numeric),
!! condense (F_a from the trailing block of L), total = order + analyze + factor +
!! condense [s], nnz(L), flops, tiles (of the dense kernels), mem = CHOLMOD's peak memory of
!! the factorization [MiB].
!!
!! Usage: bench_ordering [max_nx [threads [min_nx]]]   meshes min_nx x min_nx/2 (default 128),
!! doubled up to max_nx (default 1024)
program bench_ordering
  use, intrinsic :: iso_fortran_env, only: output_unit
  use kinds, only: wp
  use config, only: body_cfg_t, ELEM_Q1, BC_FREE, BC_CLAMPED, BC_CONTACT
  use mesh, only: mesh_t
  use assembly, only: body_system_t
  use cholesky, only: chol_t
  use errors, only: error_t
  use clock, only: wtime
  use testing, only: rectangle_body, structured_body, general_body, order_body, factor_ordered
  use omp_lib, only: omp_set_max_active_levels
  implicit none (type, external)

  character(len=*), parameter :: onames(3) = [character(len=5) :: 'metis', 'amd', 'nd']
  integer :: nx, max_nx, min_nx, threads, kind, o, stat
  character(len=32) :: arg
  type(body_cfg_t) :: b
  type(mesh_t) :: msh
  type(body_system_t) :: sys
  integer, allocatable :: last(:)

  ! as in the program with one thread: CHOLMOD's own OpenMP regions (a fixed
  ! num_threads(4)) would otherwise start 4 threads on the cores being measured
  max_nx = 1024
  threads = 1
  min_nx = 128
  if (command_argument_count() >= 1) then
    call get_command_argument(1, arg)
    read (arg, *, iostat=stat) max_nx
    if (stat /= 0) error stop 'usage: bench_ordering [max_nx [threads [min_nx]]]'
  end if
  if (command_argument_count() >= 2) then
    call get_command_argument(2, arg)
    read (arg, *, iostat=stat) threads
    if (stat /= 0 .or. threads < 1) error stop 'usage: bench_ordering [max_nx [threads [min_nx]]]'
  end if
  if (command_argument_count() >= 3) then
    call get_command_argument(3, arg)
    read (arg, *, iostat=stat) min_nx
    if (stat /= 0 .or. min_nx < 2) error stop 'usage: bench_ordering [max_nx [threads [min_nx]]]'
  end if
  call omp_set_max_active_levels(merge(0, 1, threads == 1))

  write (output_unit, '(a)') '| mesh | kind | ordering | n | m | order s | analyze s | factor s | condense s | '// &
    'total s | nnz(L) | flops | tiles | mem MiB |'
  write (output_unit, '(a)') '| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |'
  nx = min_nx
  do while (nx <= max_nx)
    b = body(nx, nx/2)
    do kind = 1, 2
      if (kind == 1) then
        call structured_body(b, msh, sys, last)
      else
        call general_body(b, 0.3_wp, 17, msh, sys, last)
      end if
      do o = 1, 3
        call one(nx, kind, o)
      end do
    end do
    nx = 2*nx
  end do

contains

  !> The paper's upper body (3 x 1, clamped on the left, contact below) with nx x ny Q1 cells.
  function body(nx, ny) result(bb)
    integer, intent(in) :: nx, ny
    type(body_cfg_t) :: bb
    bb = rectangle_body(nx, ny, ELEM_Q1, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE])
    bb%y0 = 1.0_wp
    bb%width = 3.0_wp
    bb%poisson = 0.277_wp
  end function body

  !> Order, factor and condense the current body with ordering o; print one row.
  subroutine one(nx, kind, o)
    integer, intent(in) :: nx, kind, o
    character(len=*), parameter :: kinds(2) = [character(len=10) :: 'structured', 'general']
    type(chol_t) :: ch
    integer, allocatable :: perm(:)
    real(wp), allocatable :: flex(:, :), sgn(:)
    real(wp) :: t0, t_order, t_cond
    integer :: info, m
    character(len=256) :: msg
    type(error_t) :: err

    m = size(last)
    t_order = 0.0_wp
    if (o == 3) then
      t0 = wtime()
      call order_body(msh, sys, last, perm, info, msg)
      t_order = wtime() - t0
      if (info /= 0) then
        write (output_unit, '(a)') 'nested dissection failed: '//trim(msg)
        return
      end if
    else
      allocate (perm(0))
    end if
    !$omp parallel num_threads(threads) default(shared)
    !$omp single
    call factor_ordered(ch, sys, o, last, perm, info, msg)
    !$omp end single
    !$omp end parallel
    if (info /= 0) then
      write (output_unit, '(a)') 'factor failed: '//trim(msg)
      return
    end if
    allocate (flex(m, m), sgn(m))
    sgn = -1.0_wp
    t0 = wtime()
    call ch%flexibility(last, sgn, flex, err)
    t_cond = wtime() - t0
    if (err%failed()) then
      write (output_unit, '(a)') 'flexibility failed: '//err%text()
      return
    end if
    write (output_unit, '(a,i0,a,i0,a,a,a,a,a,i0,a,i0,5(a,f0.3),a,es9.2,a,es9.2,a,i0,a,f0.0,a)') &
      '| ', nx, 'x', nx/2, ' | ', trim(kinds(kind)), ' | ', trim(onames(o)), ' | ', sys%n, ' | ', m, &
      ' | ', t_order, ' | ', ch%t_analyze, ' | ', ch%t_factor, ' | ', t_cond, ' | ', &
      t_order + ch%t_analyze + ch%t_factor + t_cond, ' | ', real(ch%nnz_factor, wp), ' | ', ch%flops, ' | ', ch%tiles, ' | ', &
      real(ch%mem_bytes, wp)/2.0_wp**20, ' |'
    flush (output_unit)
    call ch%free()
  end subroutine one

end program bench_ordering
