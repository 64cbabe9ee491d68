!> What a deck costs before anything is allocated: the memory estimate of a run (meshes,
!! assembled matrices, Cholesky factors, interface matrices) and the checks that it fits
!! the machine and the 32-bit indices of the sparse matrices; and loads whose stresses stay
!! within double precision. A deck that cannot fit is
!! bad input (exit 1) with the estimate and the limit in the message: a run must not
!! allocate until the kernel's OOM killer ends it.
!!
!! The factor estimate is calibrated on measured runs (doc/performance.md): nested
!! dissection orderings (metis, nd, amd) of a structured 2D body of n DOFs fill about
!! 8 n log2(n) entries; the banded factorization and the natural order fill n times the
!! half-bandwidth. Counts are computed in double precision, so no integer overflows.
!!
!! The MPI binary with factorization='mumps' is sized per rank (`rank_memory_mb`,
!! `check_budget_ranks`) on its bodies (`body_rank_map`): every rank meshes every body and
!! numbers its DOFs and loads, holds its share of its bodies' element entries and of their
!! MUMPS factors (a factor over the ranks of the body's group, calibrated on bench-mpi at 1024x512:
!! largest rank 2083/1188/760 MB at 1/2/4 ranks per body); the estimates of the ranks of a
!! node are summed against the node's memory, each one against ulimit -v.
module budget
  use kinds, only: wp
  use space, only: NDIM
  use config, only: MAX_SIDES, MODULUS_MIN, MODULUS_MAX, body_stiffness, deck_t, body_cfg_t, factor_cfg_t, ELEM_Q1, FACTOR_BANDED, ORDER_NATURAL
  use strings, only: i2s, sci, fixed
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  real(wp), parameter :: MIB = 1048576.0_wp
  real(wp), parameter :: INDEX_MAX = 2147483647.0_wp   ! largest 32-bit index
  real(wp), parameter :: BASE_MB = 64.0_wp             ! the program, libraries and small arrays
  real(wp), parameter :: MUMPS_OVERHEAD = 1.1_wp       ! MUMPS's working space beyond the factor
  real(wp), parameter :: COORD_MAX = 0.25_wp*sqrt(huge(1.0_wp))   ! as in mesh_topology
  real(wp), parameter :: LOAD_MAX = sqrt(huge(1.0_wp))   ! stresses and loads whose squares stay finite
  ! what else a solid body's factor can be fitted by (its fill grows as N^1.4)
  character(len=*), parameter :: REMEDY_3D = '; a solid body''s factor grows as (its DOFs)^1.4: fewer '// &
    'cells along its thickness, or the MPI binary with factorization=''mumps'' and several ranks per body'

  public :: body_memory_mb, run_memory_mb, check_budget, check_load_range, body_rank_map, rank_memory_mb, &
            check_budget_ranks

contains

  !> Memory of one body [MiB]: mesh, assembled matrix and load, factor, work vectors.
  !! `nnz_matrix` returns the matrix entries (both triangles) and `nnz_factor` the factor's.
  real(wp) function body_memory_mb(b, fc, nnz_matrix, nnz_factor) result(mb)
    type(body_cfg_t), intent(in) :: b        !< the body
    type(factor_cfg_t), intent(in) :: fc     !< its factorization
    real(wp), intent(out) :: nnz_matrix      !< stored matrix entries
    real(wp), intent(out) :: nnz_factor      !< factor entries
    real(wp) :: nodes, cells, n, half_band
    if (NDIM == 3) then
      mb = box_memory_mb(b, fc, nnz_matrix, nnz_factor)
      return
    end if
    nodes = (real(b%nx, wp) + 1.0_wp)*(real(b%ny, wp) + 1.0_wp)
    cells = real(b%nx, wp)*real(b%ny, wp)
    n = 2.0_wp*nodes
    nnz_matrix = 18.0_wp*n                    ! 9 neighbour nodes x 2 components per row
    if (fc%factorization == FACTOR_BANDED) then
      ! reverse Cuthill-McKee: the half-bandwidth follows the shorter side
      half_band = 2.0_wp*(real(min(b%nx, b%ny), wp) + 2.0_wp)
      nnz_factor = n*half_band
    else if (fc%ordering == ORDER_NATURAL) then
      ! nodes numbered along x, and the interface DOFs (at most both components of the
      ! longer side) ordered last fill their rows
      half_band = 2.0_wp*(real(b%nx, wp) + 2.0_wp)
      nnz_factor = n*half_band + n*2.0_wp*(real(max(b%nx, b%ny), wp) + 1.0_wp)
    else
      nnz_factor = 8.0_wp*n*log(max(n, 2.0_wp))/log(2.0_wp)
    end if
    mb = (16.0_wp*nodes + merge(16.0_wp, 24.0_wp, b%element == ELEM_Q1)*cells &   ! mesh
          + 12.0_wp*nnz_matrix + 64.0_wp*n &                                      ! matrix, vectors
          + 8.0_wp*nnz_factor + 4.0_wp*nnz_factor/16.0_wp)/MIB                    ! factor values, indices
  end function body_memory_mb

  !> Memory of a box body [MiB], as body_memory_mb: 27 neighbour nodes x 3 components per
  !! matrix row; the factor's fill with METIS and the contact face last follows CHOLMOD's own
  !! analysis of Q1 cubes 16^3 .. 96^3 (METHOD-3D, section 8: lnz = 11.2 N^1.4 within 5%),
  !! raised to 13 N^1.4 for the supernodal factor's storage beyond lnz (measured: 2.84 GiB for
  !! a 40^3 box of 201,720 DOFs, where 11.2 N^1.4 gives 2.5 GiB; with METIS on the node graph,
  !! 'nd', 1.13-1.28 times the entries CHOLMOD stores and 0.89-1.00 of its peak memory on the
  !! cubes 10^3 .. 40^3, bench/bench_ordering_3d.py); banded and natural orderings fill the band
  !! of the two smaller grid extents. A Gmsh volume (sized as the box of its node count) is
  !! graded: its nodes crowd where the contact is, and so do its separators. Hertz's sphere on a
  !! block at 16k ... 393k DOFs (bench/bench_hertz3d.py) stored 1.56-1.87 times 13 N^1.4; its
  !! factor is estimated at 25 N^1.4, 1.02-1.22 times what CHOLMOD stored there (over by up to 2
  !! on a uniform mesh: the check may refuse a run that would fit rather than let one overrun).
  real(wp) function box_memory_mb(b, fc, nnz_matrix, nnz_factor) result(mb)
    type(body_cfg_t), intent(in) :: b
    type(factor_cfg_t), intent(in) :: fc
    real(wp), intent(out) :: nnz_matrix, nnz_factor
    real(wp) :: nodes, cells, n, ext(3)
    ext = [real(b%nx, wp), real(b%ny, wp), real(b%nz, wp)] + 1.0_wp
    nodes = product(ext)
    cells = real(b%nx, wp)*real(b%ny, wp)*real(b%nz, wp)*merge(1.0_wp, 6.0_wp, b%element == ELEM_Q1)
    n = 3.0_wp*nodes
    nnz_matrix = 81.0_wp*n
    if (fc%factorization == FACTOR_BANDED .or. fc%ordering == ORDER_NATURAL) then
      nnz_factor = n*3.0_wp*(product(ext) / maxval(ext) + maxval(ext))
    else
      nnz_factor = merge(25.0_wp, 13.0_wp, len_trim(b%mesh) > 0)*n**1.4_wp
    end if
    mb = (24.0_wp*nodes + 40.0_wp*cells + 12.0_wp*nnz_matrix + 64.0_wp*n &
          + 8.0_wp*nnz_factor + 4.0_wp*nnz_factor/16.0_wp)/MIB
  end function box_memory_mb

  !> Memory of the whole run [MiB] (every body, interface matrices, a base).
  real(wp) function run_memory_mb(d) result(mb)
    type(deck_t), intent(in) :: d   !< the deck
    real(wp) :: nm, nf, m, ma, mtot
    integer :: a
    mb = BASE_MB
    m = 0.0_wp
    mtot = 0.0_wp
    do a = 1, d%nbody
      mb = mb + body_memory_mb(d%body(a), d%solver%factor, nm, nf)
      m = max(m, side_nodes_max(d%body(a)))
      ! several pairs: the body's contact rows, at most a side per pair it is in
      ma = side_nodes_max(d%body(a))*real(count_pairs(d, a), wp)
      if (d%npair > 1) mb = mb + 10.0_wp*8.0_wp*ma*ma/MIB   ! F_a, its operators, S, the bound's copies
      mtot = mtot + ma
    end do
    if (d%npair <= 1) then
      mb = mb + 10.0_wp*8.0_wp*m*m/MIB          ! F_1, F_2, their operators, S, the bound's copies
    else
      ! the a posteriori bound's dense H and factor, up to its size (error_estimate)
      mtot = min(0.5_wp*mtot, 6000.0_wp)
      mb = mb + 3.0_wp*8.0_wp*mtot*mtot/MIB
    end if
  end function run_memory_mb

  !> The most nodes on one side of a body: a rectangle's longer side, a box's largest face.
  real(wp) function side_nodes_max(b)
    type(body_cfg_t), intent(in) :: b
    real(wp) :: e(3)
    if (NDIM == 3) then
      e = [real(b%nx, wp), real(b%ny, wp), real(b%nz, wp)] + 1.0_wp
      side_nodes_max = product(e)/minval(e)
    else
      side_nodes_max = real(max(b%nx, b%ny), wp) + 1.0_wp
    end if
  end function side_nodes_max

  !> What else fits a solid body's factor ('' in the plane).
  function solid_remedy() result(t)
    character(len=:), allocatable :: t
    t = ''
    if (NDIM == 3) t = REMEDY_3D
  end function solid_remedy

  !> The pairs body a takes part in.
  pure integer function count_pairs(d, a) result(n)
    type(deck_t), intent(in) :: d
    integer, intent(in) :: a
    integer :: p
    n = 0
    do p = 1, d%npair
      if (any(d%pair(p)%bodies == a)) n = n + 1
    end do
    n = max(n, 1)
  end function count_pairs

  !> Refuse a deck that cannot run here: a body whose matrix or factor overflows 32-bit
  !! indices, or a run whose estimate exceeds `limit_mb` (0: no limit known): err
  !! (ERR_INPUT) naming the body, the estimate and the limit; the caller adds the deck.
  subroutine check_budget(d, limit_mb, err)
    type(deck_t), intent(in) :: d                       !< the deck
    real(wp), intent(in) :: limit_mb                    !< memory this process may use [MiB]
    type(error_t), intent(out) :: err                   !< why the run does not fit, if so
    real(wp) :: nm, nf, mb, est
    integer :: a, big
    big = 1
    do a = 1, d%nbody
      mb = body_memory_mb(d%body(a), d%solver%factor, nm, nf)
      if (mb > body_memory_mb(d%body(big), d%solver%factor, nm, nf)) big = a
      mb = body_memory_mb(d%body(a), d%solver%factor, nm, nf)
      if (nm > INDEX_MAX .or. nf > INDEX_MAX) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//' (nx = '//i2s(d%body(a)%nx)//', ny = '// &
              i2s(d%body(a)%ny)//') needs about '//fixed(nm/1.0e9_wp, '(f0.2)')//'e9 matrix and '//fixed(nf/1.0e9_wp, '(f0.2)')// &
              'e9 factor entries, beyond the 2^31 (2.1e9) that the 32-bit indices of this build hold; '// &
              'use fewer cells')
        return
      end if
    end do
    est = run_memory_mb(d)
    if (limit_mb > 0.0_wp .and. est > limit_mb .and. d%nbody == 2) then
      call err%set(ERR_INPUT, 'the run needs about '//fixed(est/1024.0_wp, '(f0.2)')// &
            ' GiB (body 1: '//fixed(body_memory_mb(d%body(1), d%solver%factor, nm, nf)/1024.0_wp, '(f0.2)')// &
            ' GiB, body 2: '//fixed(body_memory_mb(d%body(2), d%solver%factor, nm, nf)/1024.0_wp, '(f0.2)')// &
            ' GiB: meshes, matrices and Cholesky factors) but this process may use only '// &
            fixed(limit_mb/1024.0_wp, '(f0.2)')//' GiB (available memory, cgroup or ulimit -v); '// &
            'use fewer cells or a machine with more memory'//solid_remedy())
    else if (limit_mb > 0.0_wp .and. est > limit_mb) then
      call err%set(ERR_INPUT, 'the run needs about '//fixed(est/1024.0_wp, '(f0.2)')// &
            ' GiB for its '//i2s(d%nbody)//' bodies (the largest, body '//i2s(big)//': '// &
            fixed(body_memory_mb(d%body(big), d%solver%factor, nm, nf)/1024.0_wp, '(f0.2)')// &
            ' GiB: meshes, matrices and Cholesky factors) but this process may use only '// &
            fixed(limit_mb/1024.0_wp, '(f0.2)')//' GiB (available memory, cgroup or ulimit -v); '// &
            'use fewer cells or a machine with more memory'//solid_remedy())
    end if
  end subroutine check_budget

  !> The MPI binary's map of bodies to ranks (doc/running.md, "MPI: ranks and bodies"), from
  !! each body's estimated factor size w_a (`body_memory_mb`). With at least one rank per
  !! body, each body gets a group of consecutive world ranks, body 1 from rank 0: one rank
  !! each, then every further rank to the body with the largest w_a/(its ranks) (ties: the
  !! larger body, then the lower id), so the groups are proportional to the factors; two
  !! equal bodies get half each, an odd one out to body 1. With fewer ranks than bodies,
  !! each body is on one rank: the bodies, largest first, each to the least loaded rank
  !! (ties: the lower rank). `host(a)` is the world rank that leads body a's group.
  subroutine body_rank_map(d, ranks, host, group)
    type(deck_t), intent(in) :: d              !< the deck (sized: nx, ny of every body)
    integer, intent(in) :: ranks               !< ranks in the world
    integer, intent(out) :: host(:)            !< (nbody) the first world rank of each body's group
    integer, intent(out) :: group(:)           !< (nbody) the ranks of each body's group
    real(wp) :: w(d%nbody), load(max(1, ranks)), nm, total
    logical :: done(d%nbody)
    integer :: a, k, r, pick
    do a = 1, d%nbody
      total = body_memory_mb(d%body(a), d%solver%factor, nm, w(a))   ! w(a): its factor entries
    end do
    group = 1
    host = 0
    if (ranks >= d%nbody) then
      do k = d%nbody + 1, ranks
        pick = 1
        do a = 2, d%nbody
          if (w(a)/group(a) > w(pick)/group(pick) .or. &
              (w(a)/group(a) == w(pick)/group(pick) .and. w(a) > w(pick))) pick = a
        end do
        group(pick) = group(pick) + 1
      end do
      do a = 2, d%nbody
        host(a) = host(a - 1) + group(a - 1)
      end do
      return
    end if
    load = 0.0_wp
    done = .false.
    do k = 1, d%nbody
      pick = 0
      do a = 1, d%nbody   ! the largest body not placed yet (ties: the lower id)
        if (done(a)) cycle
        if (pick == 0) then
          pick = a
        else if (w(a) > w(pick)) then
          pick = a
        end if
      end do
      done(pick) = .true.
      r = minloc(load, 1)
      host(pick) = r - 1
      load(r) = load(r) + w(pick)
    end do
  end subroutine body_rank_map

  !> Memory of one rank of the MPI binary with factorization='mumps' [MiB]: the meshes,
  !! DOF numbering and loads of every body (every rank has them), its share of its bodies'
  !! element entries (triplets, and MUMPS's copy) and of their factors (MUMPS's working
  !! space included), as host of a body the right-hand side and the Schur complement and
  !! X, on world rank 0 the interface matrices of the contact iteration. The bodies of a
  !! rank are those of `body_rank_map`. `factor_share_mb` returns the factor part alone.
  real(wp) function rank_memory_mb(d, ranks, rank, factor_share_mb) result(mb)
    type(deck_t), intent(in) :: d                  !< the deck
    integer, intent(in) :: ranks                   !< ranks in the world
    integer, intent(in) :: rank                    !< this rank (0-based)
    real(wp), intent(out), optional :: factor_share_mb   !< its share of its bodies' factors [MiB]
    real(wp) :: nm, nf, ma, share, fs, iface
    integer :: a, host(d%nbody), group(d%nbody)
    call body_rank_map(d, max(1, ranks), host, group)
    mb = BASE_MB
    share = 0.0_wp
    fs = 0.0_wp
    iface = 0.0_wp
    do a = 1, d%nbody
      mb = mb + body_memory_mb(d%body(a), d%solver%factor, nm, nf) &
           - (12.0_wp*nm + 8.0_wp*nf + 4.0_wp*nf/16.0_wp)/MIB       ! mesh, vectors: every rank
      ma = real(max(d%body(a)%nx, d%body(a)%ny), wp) + 1.0_wp       ! the body's contact rows, at most
      iface = iface + 5.0_wp*8.0_wp*ma*ma/MIB
      if (rank < host(a) .or. rank >= host(a) + group(a)) cycle
      fs = fs + MUMPS_OVERHEAD*(8.0_wp*nf + 4.0_wp*nf/16.0_wp)/MIB/real(group(a), wp)
      share = share + MUMPS_OVERHEAD*12.0_wp*nm/MIB/real(group(a), wp)
      if (rank == host(a)) mb = mb + (24.0_wp*dofs(d%body(a)) + 16.0_wp*(2.0_wp*ma)**2)/MIB   ! RHS, S, X
    end do
    mb = mb + share + fs
    if (rank == 0) mb = mb + iface   ! every F_a, their operators, the bound's copies
    if (present(factor_share_mb)) factor_share_mb = fs
  end function rank_memory_mb

  !> Refuse an MPI run with factorization='mumps' that cannot run on these ranks: a rank's
  !! share beyond 32-bit indices, a rank whose estimate `rank_mb` exceeds the address-space
  !! limit `process_limit_mb`, or ranks of a node whose estimates `node_mb` (summed over the
  !! node's `node_ranks` ranks) exceed `node_limit_mb` (0: no limit known): err (ERR_INPUT)
  !! naming the estimate per rank and the limit; the caller adds the deck.
  subroutine check_budget_ranks(d, ranks, rank, rank_mb, node_mb, node_ranks, node_limit_mb, process_limit_mb, &
                                err)
    type(deck_t), intent(in) :: d                       !< the deck
    integer, intent(in) :: ranks, rank                  !< ranks in the world, this rank
    real(wp), intent(in) :: rank_mb                     !< this rank's estimate (rank_memory_mb) [MiB]
    real(wp), intent(in) :: node_mb                     !< the sum over the ranks of this node [MiB]
    integer, intent(in) :: node_ranks                   !< ranks on this node
    real(wp), intent(in) :: node_limit_mb               !< memory of the node (available, cgroup) [MiB]
    real(wp), intent(in) :: process_limit_mb            !< ulimit -v of a process [MiB]
    type(error_t), intent(out) :: err                   !< why the run does not fit, if so
    real(wp) :: fs, x
    integer :: a, host(d%nbody), group(d%nbody)
    character(len=:), allocatable :: what
    call body_rank_map(d, max(1, ranks), host, group)
    do a = 1, d%nbody
      if (dofs(d%body(a)) > INDEX_MAX .or. 9.0_wp*dofs(d%body(a))/real(group(a), wp) > INDEX_MAX) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//' (nx = '//i2s(d%body(a)%nx)//', ny = '// &
              i2s(d%body(a)%ny)//') has too many DOFs or element entries per rank for the 32-bit indices '// &
              'of this build with '//i2s(group(a))//' rank(s) on it; use more ranks or fewer cells')
        return
      end if
    end do
    x = rank_memory_mb(d, ranks, rank, fs)
    what = 'with factorization=''mumps'' on '//i2s(ranks)//' rank(s) ('//map_text(d%nbody, ranks, host, group)// &
           ') a rank needs about '//fixed(rank_mb/1024.0_wp, '(f0.2)')//' GiB (rank '//i2s(rank)// &
           ': its share of the MUMPS factor '//fixed(fs/1024.0_wp, '(f0.2)')//' GiB, the meshes and loads of '// &
           'every body and its element entries the rest)'
    if (process_limit_mb > 0.0_wp .and. rank_mb > process_limit_mb) then
      call err%set(ERR_INPUT, ''//what//' but a process may use only '// &
            fixed(process_limit_mb/1024.0_wp, '(f0.2)')//' GiB (ulimit -v); use more ranks per body or fewer cells')
    else if (node_limit_mb > 0.0_wp .and. node_mb > node_limit_mb) then
      call err%set(ERR_INPUT, ''//what//', and the '//i2s(node_ranks)//' rank(s) on its node about '// &
            fixed(node_mb/1024.0_wp, '(f0.2)')//' GiB together, but that node may use only '// &
            fixed(node_limit_mb/1024.0_wp, '(f0.2)')//' GiB (available memory, cgroup or ROBIN_MEMORY_LIMIT_MB); '// &
            'spread the ranks over more nodes (fewer per node), use more ranks per body, or fewer cells')
    end if
  end subroutine check_budget_ranks

  !> The map in words: 'g1 on body 1, g2 on body 2, ...' with a rank per body at least,
  !! otherwise 'at most k bodies per rank'.
  function map_text(nbody, ranks, host, group) result(t)
    integer, intent(in) :: nbody, ranks, host(:), group(:)
    character(len=:), allocatable :: t
    integer :: a, r, most
    if (ranks >= nbody) then
      t = ''
      do a = 1, nbody
        if (a > 1) t = t//', '
        t = t//i2s(group(a))//' on body '//i2s(a)
      end do
    else
      most = 0
      do r = 0, ranks - 1
        most = max(most, count(host == r))
      end do
      t = 'one rank per body, at most '//i2s(most)//' bodies per rank'
    end if
  end function map_text

  !> Unknowns of a structured body (both components of every node).
  real(wp) function dofs(b)
    type(body_cfg_t), intent(in) :: b
    dofs = 2.0_wp*(real(b%nx, wp) + 1.0_wp)*(real(b%ny, wp) + 1.0_wp)
    if (NDIM == 3) dofs = 3.0_wp*(real(b%nx, wp) + 1.0_wp)*(real(b%ny, wp) + 1.0_wp)*(real(b%nz, wp) + 1.0_wp)
  end function dofs

  !> Loads within double precision: a traction (pressure included) or prescribed displacement
  !! whose stresses or loads would reach LOAD_MAX (1.3e154 Pa, beyond which their squares in
  !! the solvers' norms overflow) is refused, with a margin of 1e6 for the products of
  !! assembly and stress recovery: err (ERR_INPUT) naming the load and the value; the
  !! caller adds the deck.
  subroutine check_load_range(d, err)
    type(deck_t), intent(in) :: d                       !< the deck
    type(error_t), intent(out) :: err                   !< why the loads are not representable, if so
    real(wp), parameter :: MARGIN = 1.0e6_wp
    real(wp) :: ext, t, h, u, cap, ymin, hx, hy, rho, elo, ehi
    integer :: i, a, s
    ! a stiffness (of the order of young) and a flexibility (of 1/young) whose squares stay finite
    do a = 1, d%nbody
      call body_stiffness(d%body(a), elo, ehi)
      if (.not. (ehi < MODULUS_MAX .and. elo > MODULUS_MIN)) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//': '//modulus(a, merge(ehi, elo, ehi >= MODULUS_MAX))// &
              ' is outside ['// &
              sci(MODULUS_MIN)//', '//sci(MODULUS_MAX)//'], where its stiffness and flexibility '// &
              'stay within double precision; rescale the units')
        return
      end if
    end do
    ext = 1.0_wp
    do a = 1, d%nbody
      if (len_trim(d%body(a)%mesh) > 0) cycle
      ! the Gmsh reader's bound on coordinates (mesh_topology), here for a rectangle
      ext = max(abs(d%body(a)%x0) + d%body(a)%width, abs(d%body(a)%y0) + d%body(a)%height)
      if (.not. ext <= COORD_MAX) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//': its rectangle reaches a coordinate of magnitude '// &
              sci(ext)//': beyond '//sci(COORD_MAX)//' the cells'' areas overflow double precision; '// &
              'scale the geometry')
        return
      end if
      ! an element's stiffness holds young/h and young (longer side)/(shorter side)
      hx = d%body(a)%width/real(d%body(a)%nx, wp)
      hy = d%body(a)%height/real(d%body(a)%ny, wp)
      call body_stiffness(d%body(a), elo, ehi)
      if (.not. log(ehi) + log(max(1.0_wp, hx, hy)) - log(min(hx, hy)) + log(MARGIN) &
          < log(LOAD_MAX)) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//': its cells of '//sci(hx)//' x '//sci(hy)// &
              ' [length] with '//modulus(a, ehi)//' have a stiffness beyond double '// &
              'precision; rescale the geometry or the units')
        return
      end if
    end do
    ext = 1.0_wp
    ymin = huge(1.0_wp)
    do a = 1, d%nbody
      ext = max(ext, abs(d%body(a)%x0) + d%body(a)%width, abs(d%body(a)%y0) + d%body(a)%height)
      call body_stiffness(d%body(a), elo, ehi)
      ymin = min(ymin, elo)
    end do
    ! every product below stays finite (no overflow trap in the checked build): ext is a
    ! coordinate extent, at most COORD_MAX, far below huge/MARGIN
    cap = LOAD_MAX/(ext*MARGIN)
    do i = 1, d%ntraction
      t = maxval(abs(d%traction(i)%t0)) + abs(d%traction(i)%pressure)
      if (maxval(abs(d%traction(i)%t1)) < cap/ext) then
        t = t + maxval(abs(d%traction(i)%t1))*ext
      else
        t = huge(1.0_wp)
      end if
      if (.not. t < cap) then
        call err%set(ERR_INPUT, '&traction '//i2s(i)//' (body '//i2s(d%traction(i)%body)// &
              ') reaches '//sci(t)//' [stress]: its stresses would overflow double precision; '// &
              'rescale the units (e.g. &scene units=''mm-N-MPa'')')
        return
      end if
      ! the displacements it causes, of the order of t ext / young in the softer body
      if (t > 0.0_wp) then
        if (.not. log(t) + log(ext) - log(ymin) + log(MARGIN) < log(LOAD_MAX)) then
          call err%set(ERR_INPUT, '&traction '//i2s(i)//' (body '//i2s(d%traction(i)%body)// &
                ') reaches '//sci(t)//' [stress] with young = '//sci(ymin)//': its displacements '// &
                'would overflow double precision; rescale the units')
          return
        end if
      end if
    end do
    ! a body force b [force/length^3] makes stresses of about b ext: as a traction of b ext
    do i = 1, d%nbody_force
      do a = 1, d%nbody
        if (d%body_force(i)%body /= 0 .and. d%body_force(i)%body /= a) cycle
        t = huge(1.0_wp)
        rho = d%body(a)%density                     ! the largest density of its materials
        if (allocated(d%body(a)%law)) rho = maxval(d%body(a)%law%density)
        if (rho < cap/ext .and. maxval(abs(d%body_force(i)%gravity)) < cap/ext &
            .and. maxval(abs(d%body_force(i)%force)) < cap/ext) then
          ! (Fortran's .or. may evaluate both sides: no quotient by a zero density)
          if (rho == 0.0_wp) then
            t = maxval(abs(d%body_force(i)%force))*ext
          else if (maxval(abs(d%body_force(i)%gravity)) < cap/(ext*rho)) then
            t = (rho*maxval(abs(d%body_force(i)%gravity)) + maxval(abs(d%body_force(i)%force)))*ext
          end if
        end if
        if (.not. t < cap .or. .not. log(max(t, tiny(1.0_wp))) + log(ext) - log(ymin) + log(MARGIN) < log(LOAD_MAX)) then
          ! (the inputs named, not t: the product itself may be beyond double precision)
          call err%set(ERR_INPUT, trim(d%body_force(i)%origin)//' on body '//i2s(a)//' (density '// &
                sci(rho)//', gravity up to '//sci(maxval(abs(d%body_force(i)%gravity)))// &
                ', force up to '//sci(maxval(abs(d%body_force(i)%force)))//' over the scene''s extent '// &
                sci(ext)//' [length]) makes stresses or displacements beyond double precision; rescale '// &
                'the units (e.g. &scene units=''mm-N-MPa'')')
          return
        end if
      end do
    end do
    do a = 1, d%nbody
      h = min(d%body(a)%width/real(d%body(a)%nx, wp), d%body(a)%height/real(d%body(a)%ny, wp))
      do s = 1, MAX_SIDES
        u = maxval(abs(d%body(a)%u_side(:, s)))
        if (.not. u > 0.0_wp) cycle   ! (no short-circuit in Fortran: log(0) must not be evaluated)
        call body_stiffness(d%body(a), elo, ehi)
        if (.not. log(u) + log(ehi) - log(h) + log(MARGIN) < log(LOAD_MAX)) then
          call err%set(ERR_INPUT, 'the &displacement of body '//i2s(a)//' ('//sci(u)// &
                ' [length]) with '//modulus(a, ehi)//' gives stresses beyond double '// &
                'precision; rescale the units')
          return
        end if
      end do
    end do
    ! on a group the mesh size is not known yet, but the loads K u of a plane element's
    ! stiffness K (entries of the order of young) must stay finite
    do i = 1, d%nboundary
      a = d%boundary(i)%body
      if (a < 1 .or. a > d%nbody) cycle
      u = maxval(abs(d%boundary(i)%u), mask=d%boundary(i)%fix)
      if (.not. u > 0.0_wp) cycle
      call body_stiffness(d%body(a), elo, ehi)
      if (.not. log(u) + log(ehi) + log(MARGIN) < log(LOAD_MAX)) then
        call err%set(ERR_INPUT, '&boundary '//i2s(i)//' (body '//i2s(a)//", group '"// &
              trim(d%boundary(i)%group)//"') prescribes "//sci(u)//' [length] with '// &
              modulus(a, ehi)//': its loads would overflow double precision; rescale the units')
        return
      end if
    end do
  contains
    !> 'young = X' for a body of young and poisson, else 'a stiffness of X (its materials)'.
    function modulus(a, x) result(txt)
      integer, intent(in) :: a
      real(wp), intent(in) :: x
      character(len=:), allocatable :: txt
      if (len_trim(d%body(a)%material) == 0 .and. d%nregion == 0) then
        txt = 'young = '//sci(x)
      else
        txt = 'a stiffness of '//sci(x)//' (its materials'' moduli)'
      end if
    end function modulus
  end subroutine check_load_range

end module budget
