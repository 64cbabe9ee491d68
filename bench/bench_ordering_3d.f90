!> Benchmark of the fill-reducing orderings of one solid body (prints, asserts nothing).
!!
!! The k^3 cube of hexahedra of METHOD-3D's table (the unit cube, Q1, steel, the bottom
!! clamped; testing's box_system), the normal (y) DOFs of its top face, the contact face,
!! ordered last, factored by CHOLMOD with one ordering:
!!   nodes        METIS on the node graph (ordering%node_dissection, ORD_NODES: what
!!                ordering='nd' gives a solid body), the contact DOFs last
!!   metis        METIS on the DOF graph (CHOLMOD's cholmod_metis of the interior, ORD_METIS:
!!                what 'nd' gave before), the contact DOFs last
!!   auto         CHOLMOD's own analysis with its default strategy (nmethods = 0: AMD, and
!!                METIS too when AMD fills much; the better kept), nothing last (it cannot)
!!   nodes-plain, metis-plain   the first two with nothing last (auto's like)
!! One thread by default (the shim holds OpenBLAS to one; a second OpenMP thread runs the
!! tiles of the large dense kernels, as in the program).
!!
!! Prints one line of key=value pairs: k, n (free DOFs), ndof (all DOFs: the memory check's
!! N), m, ordering, t_order (the permutation, a part of t_analyze; 0 for auto, whose
!! ordering runs inside the analysis), t_analyze (ordering + symbolic), t_factor (numeric)
!! [s], lnz = nnz(L), lsize (entries stored in the supernodal L), flops, mem_mib (CHOLMOD's
!! peak), used (the ordering CHOLMOD kept: 1 given, 2 AMD, 3 METIS), rss_mib (the process's
!! peak resident memory), and the memory check's estimate (budget%body_memory_mb of a box):
!! est_entries = 13 N^1.4, est_factor_mib (its 8.25 bytes per entry), est_body_mib.
!!
!! Usage: bench_ordering_3d k ordering [threads]
program bench_ordering_3d
  use, intrinsic :: iso_fortran_env, only: output_unit
  use kinds, only: wp
  use space, only: set_dimension
  use config, only: body_cfg_t, factor_cfg_t, ELEM_Q1, BC_FREE, BC_CLAMPED, BC_CONTACT, ORDER_ND
  use mesh, only: mesh_t
  use assembly, only: body_system_t
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_NODES, ORD_METIS, ORD_AUTO
  use budget, only: body_memory_mb
  use sysinfo, only: peak_rss_mb
  use errors, only: error_t
  use testing, only: box_system
  use omp_lib, only: omp_set_max_active_levels
  implicit none (type, external)

  character(len=*), parameter :: usage = 'usage: bench_ordering_3d k nodes|metis|auto|nodes-plain|metis-plain [threads]'
  integer :: k, threads, stat, ord
  logical :: with_last
  character(len=32) :: arg, oname
  type(mesh_t) :: msh
  type(body_system_t) :: sys
  type(chol_t) :: ch
  type(body_cfg_t) :: b
  type(factor_cfg_t) :: fc
  type(error_t) :: err
  integer, allocatable :: last(:), none(:)
  real(wp) :: est_mb, nnz_matrix, est_entries

  if (command_argument_count() < 2) error stop usage
  call get_command_argument(1, arg)
  read (arg, *, iostat=stat) k
  if (stat /= 0 .or. k < 1) error stop usage
  call get_command_argument(2, oname)
  threads = 1
  if (command_argument_count() >= 3) then
    call get_command_argument(3, arg)
    read (arg, *, iostat=stat) threads
    if (stat /= 0 .or. threads < 1) error stop usage
  end if
  select case (trim(oname))
  case ('nodes', 'nodes-plain')
    ord = ORD_NODES
  case ('metis', 'metis-plain')
    ord = ORD_METIS
  case ('auto')
    ord = ORD_AUTO
  case default
    error stop usage
  end select
  with_last = trim(oname) == 'nodes' .or. trim(oname) == 'metis'
  call omp_set_max_active_levels(merge(0, 1, threads == 1))

  call set_dimension(3)
  call box_system(k, k, k, ELEM_Q1, [BC_FREE, BC_FREE, BC_CLAMPED, BC_CONTACT, BC_FREE, BC_FREE], msh, sys, last)
  allocate (none(0))
  if (.not. with_last) call move_alloc(none, last)

  !$omp parallel num_threads(threads) default(shared)
  !$omp single
  call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ord, err, last=last)
  !$omp end single
  !$omp end parallel
  if (err%failed()) then
    write (output_unit, '(a)') 'error='//err%text()
    error stop 1
  end if

  ! the memory check's estimate for this box (budget%body_memory_mb of a box, ordering 'nd')
  b%nx = k
  b%ny = k
  b%nz = k
  b%element = ELEM_Q1
  fc%ordering = ORDER_ND
  est_mb = body_memory_mb(b, fc, nnz_matrix, est_entries)

  write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a,a,a,l1,3(a,f0.4),a,i0,a,i0,a,es12.5,a,f0.1,a,i0,a,f0.1,a,es12.5,a,f0.1,a,f0.1)') &
    'k=', k, ' n=', sys%n, ' ndof=', sys%ndof, ' m=', size(last), ' ordering=', trim(oname), ' last=', with_last, &
    ' t_order=', ch%t_order, ' t_analyze=', ch%t_analyze, ' t_factor=', ch%t_factor, &
    ' lnz=', ch%nnz_factor, ' lsize=', ch%nnz_stored, ' flops=', ch%flops, ' mem_mib=', real(ch%mem_bytes, wp)/2.0_wp**20, &
    ' used=', ch%ordering_used, ' rss_mib=', peak_rss_mb(), ' est_entries=', est_entries, &
    ' est_factor_mib=', (8.0_wp + 4.0_wp/16.0_wp)*est_entries/2.0_wp**20, ' est_body_mib=', est_mb
  call ch%free()
end program bench_ordering_3d
