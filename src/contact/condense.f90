!> Interface condensation: for each body, on its contact rows of every pair it takes part
!! in (module contact_interface), its factorization, its normal flexibility
!! F_a = B_a K_a^-1 B_a' and the normal interface displacement under the load alone
!! b_a = B_a K_a^-1 f_a (plus B_a's part on prescribed DOFs) (doc/method.md). The free DOFs
!! that B_a touches are ordered last in the factorization, so F_a comes from the trailing
!! block of the factor at a cost of O(k^3) (k those DOFs), not m solves. The body owns its
!! factorization as one `class(factor_t)` (module factorization: CHOLMOD, banded or MUMPS,
!! picked by `new_factor` from the deck's setting), so the serial and the MPI path condense
!! and recover through the same routines; with MUMPS they are collective over the body's
!! group of ranks and the results are on its host.
module condense
  use kinds, only: wp
  use space, only: NCOMP, node_dof, dof_node, dof_comp
  use, intrinsic :: ieee_exceptions, only: ieee_usual, ieee_get_halting_mode, ieee_set_halting_mode
  use config, only: factor_cfg_t
  use mesh, only: mesh_t
  use contact_interface, only: interface_t, body_slots, slot_row, slot_side
  use assembly, only: body_system_t
  use factorization, only: factor_t, new_factor, flex_product
  use ordering, only: grid_dissection, coordinate_bisection
  use clock, only: wtime
  use errors, only: error_t, ERR_MEMORY
  use lapack, only: dpotrf_tiles, dpotrs, dpocon, dpstrf, dsyevr, dsyevd, dsyev, dgemm, dgeqrf, dorgqr, dsytrf, &
                    tiles_begin, tiles_end, tiles_pause, tiles_resume
  use iso_c_binding, only: c_long, c_int
  implicit none (type, external)
  private

  !> A singular F_a's kernel basis takes in its near-kernel too: the eigenvectors of the
  !! eigenvalues up to this times max diag F_a (flex_rank; the level below which its
  !! condition estimate does not call F_a plainly of full rank either)
  real(wp), parameter :: NEAR_KERNEL = 1.0e-6_wp
  !> F_a of at least this order gets its (near-)kernel basis by subspace iteration
  !! (smallest_eigenvectors) instead of LAPACK's tridiagonal reduction (every plane deck's
  !! F_a is smaller)
  integer, parameter, public :: SUBSPACE_MIN = 1500

  !> One body reduced to the interface.
  type, public :: body_condensed_t
    integer :: m = 0                        !< the body's contact rows, over all its pairs
    !> (m) where the body's rows sit in the (M, 2) side layout of the contact vectors
    !! (contact_interface `body_slots`): the body's own vector is x(slots) of such an x
    integer, allocatable :: slots(:)
    integer :: n = 0                        !< free DOFs of the body
    integer, allocatable :: idx(:)          !< (k) the free DOFs B_a touches, ordered last
    integer, allocatable :: bptr(:)         !< (m+1) B_a on them: row i is entries bptr(i)..bptr(i+1)-1,
    integer, allocatable :: bpos(:)         !<   position in idx of each entry
    real(wp), allocatable :: bval(:)        !<   and its coefficient
    real(wp), allocatable :: bfix(:)        !< (m) B_a's part on prescribed DOFs, B_a,d u_d [length]
    !> Contact frames (contact_frames): the nodes whose displacement the factorization sees in
    !! the frame of the one contact row that acts on them alone (a slave node: its normal n
    !! and tangents), so that row touches one DOF. The factor is that of T'K_a T, every
    !! vector of the factorization's (u0, the solves, B_a's rows above) is in those frames,
    !! u = T u~; nrot = 0: none
    integer :: nrot = 0
    integer, allocatable :: rot_dof(:, :)   !< (NCOMP, nrot) the free DOFs of each node (consecutive)
    real(wp), allocatable :: rot(:, :, :)   !< (NCOMP, NCOMP, nrot) its frame R, columns n, t1 (, t2) [-]
    real(wp), allocatable :: flex(:, :)     !< (m,m) F_a [length/force]
    !> > 0 when F_a is singular (mortar: a master surface coarser than the slave has fewer
    !! normal DOFs than the slave has rows): then the body's subproblem gets a proximal term
    !! that pins its multipliers to the other body's (robin_operators `proximal_term`);
    !! its value, 1e-2 max diag F_a, is the scale of F_a
    real(wp) :: prox = 0.0_wp             !< [length/force]
    integer :: rank = 0                   !< numerical rank of F_a
    !> (m, m - rank) orthonormal basis Z of the numerical kernel of F_a and, when there is
    !! one, of its near-kernel (unallocated when F_a is nonsingular): the proximal term and
    !! the obstacle act on Z Z' only (robin_operators)
    real(wp), allocatable :: kern(:, :)
    !> (m, rank) when the kernel is the larger part (F_a built from fewer interface DOFs than
    !! rows, at most half as many: a master surface much coarser than the slave), the
    !! orthonormal basis Q of F_a's range instead of kern (then Z Z' = I - Q Q'); at most one
    !! of kern and rng is allocated
    real(wp), allocatable :: rng(:, :)
    !> A body held only by contact (assembly: sys%nrig > 0): K_a^-1 above is the generalized
    !! inverse K_a^+ of the factor with the fixing DOFs removed, and the equilibrium of the
    !! body is the equality G_a lam = e_a on its contact forces (module floating)
    integer :: nrig = 0                     !< rigid motions the supports leave free
    real(wp), allocatable :: rg(:, :)       !< (nrig, m) G_a = R_a' B_a' [-]
    real(wp), allocatable :: re(:)          !< (nrig) e_a = R_a' f_a [force]
    !> (nrig, nrig) S_kl = sum over B_a's entries of coef^2 (r_k . r_l) at the entry's node: v'S v
    !! is what |G_a' v|^2 would be if every contact normal were along the motion R_a v
    real(wp), allocatable :: rreach(:, :)
    real(wp), allocatable :: b(:)           !< (m) B_a K_a^-1 f_a [length]
    !> (n) K_a^-1 f_a [length]; not kept with a distributed factor (MUMPS), whose
    !! displacement recovery solves with f_a - B_a' lam instead
    real(wp), allocatable :: u0(:)
    class(factor_t), allocatable :: fac     !< the factorization of K_a
    real(wp) :: t_factor = 0.0_wp           !< wall time of analyze + factorize [s]
    real(wp) :: t_condense = 0.0_wp         !< wall time of F_a and b_a [s]
  end type body_condensed_t

  public :: smallest_eigenvectors, factor_body, condense_body, interface_load, recover_displacement, apply_bt, apply_b, interface_dofs, &
            flex_from_x, prescribed_part, to_global, contact_frames, frame_of_normal, rotated_values, rotated_triplets

contains

  !> B_a on the free DOFs of body a (its sides of the rows of every pair it is in, in the
  !! order of `body_slots`): the DOFs it touches with a non-zero coefficient, in the order
  !! the rows first touch them (these are ordered last in the factorization), the rows over
  !! their positions, and the constant part on prescribed DOFs.
  subroutine interface_dofs(itf, a, sys, cbody)
    type(interface_t), intent(in) :: itf             !< the contact rows of all pairs
    integer, intent(in) :: a                         !< body number
    type(body_system_t), intent(in) :: sys           !< assembled system of body a
    type(body_condensed_t), intent(inout) :: cbody   !< receives m, n, slots, idx and the rows on it
    integer :: i, e, p, k, ne, row, side, total
    integer, allocatable :: pos_of(:), idx(:)

    cbody%slots = body_slots(itf, a)
    cbody%m = size(cbody%slots)
    cbody%n = sys%n
    if (allocated(cbody%idx)) deallocate (cbody%idx)
    if (allocated(cbody%bptr)) deallocate (cbody%bptr, cbody%bpos, cbody%bval, cbody%bfix)
    total = 0
    do i = 1, cbody%m
      row = slot_row(cbody%slots(i), itf%m)
      side = slot_side(cbody%slots(i), itf%m)
      total = total + itf%b(side)%ptr(row + 1) - itf%b(side)%ptr(row)
    end do
    allocate (pos_of(sys%n), idx(total), cbody%bptr(cbody%m + 1), cbody%bpos(total), cbody%bval(total), cbody%bfix(cbody%m))
    pos_of = 0
    k = 0
    ne = 0
    cbody%bptr(1) = 1
    do i = 1, cbody%m
      row = slot_row(cbody%slots(i), itf%m)
      side = slot_side(cbody%slots(i), itf%m)
      associate (b => itf%b(side))
        do e = b%ptr(row), b%ptr(row + 1) - 1
          if (b%val(e) == 0.0_wp) cycle
          p = sys%free_of(b%dof(e))
          if (p == 0) cycle
          if (pos_of(p) == 0) then
            k = k + 1
            idx(k) = p
            pos_of(p) = k
          end if
          ne = ne + 1
          cbody%bpos(ne) = pos_of(p)
          cbody%bval(ne) = b%val(e)
        end do
      end associate
      cbody%bptr(i + 1) = ne + 1
    end do
    cbody%idx = idx(1:k)
    call prescribed_part(itf, sys, cbody)
    call contact_frames(sys, cbody)
  end subroutine interface_dofs

  !> The contact frames: a row whose entries on free DOFs all lie on one node, on two or more
  !! of its components, with every component of that node free (a curved or inclined slave
  !! node's row D_jj n_j . u_j), turns that node's displacement into the row's frame
  !! R = [n, t1 (, t2)] (n its direction; t1 along the axis least aligned with n crossed
  !! with n, t2 = n x t1), the first such row for each node; B_a's rows are rewritten on
  !! those frames (B_a T), where the defining row touches the node's first DOF alone. Nodes
  !! whose columns of K_a do not share one pattern keep the global frame. The factor then
  !! orders one DOF per such row last instead of NCOMP, and the dense trailing block and its
  !! inverse shrink by NCOMP^3 (doc/method.md, "Contact frames").
  subroutine contact_frames(sys, cbody)
    type(body_system_t), intent(in) :: sys           !< the body's DOF map and pattern
    type(body_condensed_t), intent(inout) :: cbody   !< its rows on the free DOFs; gets the frames
    integer, allocatable :: rot_of(:), nidx(:), pos_of(:), nbpos(:), nbptr(:)
    real(wp), allocatable :: nbval(:), rtmp(:, :, :)
    integer, allocatable :: dtmp(:, :)
    integer :: i, e, p, nd, node, c, k, ne, nr, j, p1, q
    real(wp) :: v(NCOMP), w(NCOMP), vn
    logical :: one
    cbody%nrot = 0
    if (allocated(cbody%rot)) deallocate (cbody%rot, cbody%rot_dof)
    if (cbody%m == 0) return
    allocate (rot_of(sys%n), dtmp(NCOMP, cbody%m), rtmp(NCOMP, NCOMP, cbody%m))
    rot_of = 0
    nr = 0
    do i = 1, cbody%m
      if (cbody%bptr(i + 1) - cbody%bptr(i) < 2) cycle
      node = dof_node(sys%dof_of(cbody%idx(cbody%bpos(cbody%bptr(i)))))
      one = .true.
      v = 0.0_wp
      do e = cbody%bptr(i), cbody%bptr(i + 1) - 1
        nd = sys%dof_of(cbody%idx(cbody%bpos(e)))
        if (dof_node(nd) /= node) one = .false.
        if (one) v(dof_comp(nd)) = v(dof_comp(nd)) + cbody%bval(e)
      end do
      if (.not. one) cycle
      p1 = sys%free_of(node_dof(node, 1))
      if (p1 == 0 .or. rot_of(max(p1, 1)) /= 0) cycle
      if (.not. all([(sys%free_of(node_dof(node, c)) == p1 + c - 1, c=1, NCOMP)])) cycle
      if (.not. same_columns(p1)) cycle
      vn = norm2(v)
      if (.not. (vn > 0.0_wp)) cycle
      nr = nr + 1
      dtmp(:, nr) = [(p1 + c - 1, c=1, NCOMP)]
      rtmp(:, :, nr) = frame_of_normal(v/vn)
      rot_of(p1:p1 + NCOMP - 1) = nr
    end do
    if (nr == 0) return
    ! B_a T: each row's entries on a rotated node become R' v, the defining row's exactly
    ! (|v|, 0, ...); components below 1e-13 |v| are rounding of an orthogonal frame
    allocate (nidx(sys%n), pos_of(sys%n), nbpos(size(cbody%bval) + NCOMP*cbody%m), nbval(size(cbody%bval) + NCOMP*cbody%m), &
              nbptr(cbody%m + 1))
    pos_of = 0
    k = 0
    ne = 0
    nbptr(1) = 1
    do i = 1, cbody%m
      do e = cbody%bptr(i), cbody%bptr(i + 1) - 1
        p = cbody%idx(cbody%bpos(e))
        j = rot_of(p)
        if (j == 0) then
          call put(p, cbody%bval(e))
          cycle
        end if
        if (p /= cbody%idx(cbody%bpos(first_on(i, j)))) cycle     ! the node's entries, once
        v = 0.0_wp
        do q = cbody%bptr(i), cbody%bptr(i + 1) - 1
          if (rot_of(cbody%idx(cbody%bpos(q))) == j) v(cbody%idx(cbody%bpos(q)) - dtmp(1, j) + 1) = cbody%bval(q)
        end do
        w = matmul(transpose(rtmp(:, :, j)), v)
        vn = norm2(v)
        if (abs(w(1) - vn) <= 1.0e-13_wp*vn .and. all(abs(w(2:)) <= 1.0e-13_wp*vn)) w = [vn, (0.0_wp, c=2, NCOMP)]
        do c = 1, NCOMP
          if (abs(w(c)) > 1.0e-13_wp*vn) call put(dtmp(c, j), w(c))
        end do
      end do
      nbptr(i + 1) = ne + 1
    end do
    cbody%nrot = nr
    cbody%rot_dof = dtmp(:, 1:nr)
    cbody%rot = rtmp(:, :, 1:nr)
    cbody%idx = nidx(1:k)
    cbody%bptr = nbptr
    cbody%bpos = nbpos(1:ne)
    cbody%bval = nbval(1:ne)

  contains

    !> One entry of the new row i on free DOF p.
    subroutine put(p, val)
      integer, intent(in) :: p
      real(wp), intent(in) :: val
      if (pos_of(p) == 0) then
        k = k + 1
        nidx(k) = p
        pos_of(p) = k
      end if
      ne = ne + 1
      nbpos(ne) = pos_of(p)
      nbval(ne) = val
    end subroutine put

    !> The first entry of row i on rotated node j.
    integer function first_on(i, j) result(ef)
      integer, intent(in) :: i, j
      do ef = cbody%bptr(i), cbody%bptr(i + 1) - 1
        if (rot_of(cbody%idx(cbody%bpos(ef))) == j) return
      end do
    end function first_on

    !> The columns of the node's DOFs p1 .. p1 + NCOMP - 1 have one pattern (rows), which
    !! rotated_values needs (the triplets of a distributed factor do not).
    logical function same_columns(p1)
      integer, intent(in) :: p1
      integer :: c, l
      same_columns = .true.
      if (.not. allocated(sys%colptr)) return     ! a distributed factor takes triplets: any pattern
      l = sys%colptr(p1 + 1) - sys%colptr(p1)
      do c = 1, NCOMP - 1
        if (sys%colptr(p1 + c + 1) - sys%colptr(p1 + c) /= l) then
          same_columns = .false.
          return
        end if
        if (any(sys%rowind(sys%colptr(p1 + c) + 1:sys%colptr(p1 + c + 1)) /= &
                sys%rowind(sys%colptr(p1) + 1:sys%colptr(p1 + 1)))) then
          same_columns = .false.
          return
        end if
      end do
    end function same_columns

  end subroutine contact_frames

  !> An orthonormal frame whose first column is the unit vector n: in the plane [n, t] with
  !! t = (-n_y, n_x); in space t1 = a x n / |a x n| (a the axis least aligned with n),
  !! t2 = n x t1.
  pure function frame_of_normal(n) result(r)
    real(wp), intent(in) :: n(:)
    real(wp) :: r(size(n), size(n)), a(3), t1(3)
    integer :: c
    r(:, 1) = n
    if (size(n) == 2) then
      r(:, 2) = [-n(2), n(1)]
      return
    end if
    a = 0.0_wp
    c = minloc(abs(n), dim=1)
    a(c) = 1.0_wp
    t1 = [a(2)*n(3) - a(3)*n(2), a(3)*n(1) - a(1)*n(3), a(1)*n(2) - a(2)*n(1)]
    t1 = t1/norm2(t1)
    r(:, 2) = t1
    r(:, 3) = [n(2)*t1(3) - n(3)*t1(2), n(3)*t1(1) - n(1)*t1(3), n(1)*t1(2) - n(2)*t1(1)]
  end function frame_of_normal

  !> v = T v~ (to the global frame) or, with inverse, v~ = T' v: the rotated nodes' triples.
  pure subroutine to_global(cbody, v, inverse)
    type(body_condensed_t), intent(in) :: cbody      !< the body's frames
    real(wp), intent(inout) :: v(:)                  !< (n) a vector of free DOFs
    logical, intent(in), optional :: inverse
    integer :: j
    logical :: inv
    inv = .false.
    if (present(inverse)) inv = inverse
    do j = 1, cbody%nrot
      if (inv) then
        v(cbody%rot_dof(:, j)) = matmul(transpose(cbody%rot(:, :, j)), v(cbody%rot_dof(:, j)))
      else
        v(cbody%rot_dof(:, j)) = matmul(cbody%rot(:, :, j), v(cbody%rot_dof(:, j)))
      end if
    end do
  end subroutine to_global

  !> T'K_a T in CSC (the pattern of K_a: a rotated node's columns share one pattern and its
  !! DOFs are consecutive rows): first the columns of each rotated node (K R), then in every
  !! column the rotated nodes' rows (R' (K R)).
  subroutine rotated_values(sys, cbody, val)
    type(body_system_t), intent(in) :: sys
    type(body_condensed_t), intent(in) :: cbody
    real(wp), allocatable, intent(out) :: val(:)
    integer, allocatable :: rot_row(:)
    integer :: j, c, l, q, q0, len
    real(wp), allocatable :: cols(:, :)
    val = sys%val
    allocate (rot_row(sys%n))
    rot_row = 0
    do j = 1, cbody%nrot
      rot_row(cbody%rot_dof(1, j)) = j
      q0 = sys%colptr(cbody%rot_dof(1, j))
      len = sys%colptr(cbody%rot_dof(1, j) + 1) - q0
      allocate (cols(len, NCOMP))
      do c = 1, NCOMP
        cols(:, c) = val(sys%colptr(cbody%rot_dof(c, j)) + 1:sys%colptr(cbody%rot_dof(c, j)) + len)
      end do
      cols = matmul(cols, cbody%rot(:, :, j))
      do c = 1, NCOMP
        val(sys%colptr(cbody%rot_dof(c, j)) + 1:sys%colptr(cbody%rot_dof(c, j)) + len) = cols(:, c)
      end do
      deallocate (cols)
    end do
    do l = 1, sys%n
      q = sys%colptr(l) + 1
      do while (q <= sys%colptr(l + 1))
        j = rot_row(sys%rowind(q) + 1)
        if (j > 0) then
          val(q:q + NCOMP - 1) = matmul(transpose(cbody%rot(:, :, j)), val(q:q + NCOMP - 1))
          q = q + NCOMP
        else
          q = q + 1
        end if
      end do
    end do
  end subroutine rotated_values

  !> T'K_a T as triplets of its lower triangle, from K_a's (lower triangle, duplicates to be
  !! summed): an entry on a rotated node is taken with its mirror, spread over the frames of
  !! its row's and its column's nodes, and kept where it falls on or below the diagonal.
  subroutine rotated_triplets(cbody, n, irn, jcn, kval, ri, rj, rv)
    type(body_condensed_t), intent(in) :: cbody
    integer, intent(in) :: n, irn(:), jcn(:)
    real(wp), intent(in) :: kval(:)
    integer, allocatable, intent(out) :: ri(:), rj(:)
    real(wp), allocatable, intent(out) :: rv(:)
    integer, allocatable :: rot_of(:)
    integer :: e, q, a, b, ja, jb, ca, cb, na, nb, side, r0, c0, i1, j1
    allocate (rot_of(n))
    rot_of = 0
    do ja = 1, cbody%nrot
      rot_of(cbody%rot_dof(:, ja)) = ja
    end do
    q = 0
    do e = 1, size(irn)
      if (rot_of(irn(e)) > 0 .or. rot_of(jcn(e)) > 0) then
        q = q + 2*NCOMP*NCOMP
      else
        q = q + 1
      end if
    end do
    allocate (ri(q), rj(q), rv(q))
    q = 0
    do e = 1, size(irn)
      if (rot_of(irn(e)) == 0 .and. rot_of(jcn(e)) == 0) then
        q = q + 1
        ri(q) = irn(e)
        rj(q) = jcn(e)
        rv(q) = kval(e)
        cycle
      end if
      do side = 1, merge(1, 2, irn(e) == jcn(e))
        i1 = merge(irn(e), jcn(e), side == 1)
        j1 = merge(jcn(e), irn(e), side == 1)
        ja = rot_of(i1)
        jb = rot_of(j1)
        na = merge(NCOMP, 1, ja > 0)
        nb = merge(NCOMP, 1, jb > 0)
        do a = 1, na
          r0 = i1
          if (ja > 0) r0 = cbody%rot_dof(a, ja)
          do b = 1, nb
            c0 = j1
            if (jb > 0) c0 = cbody%rot_dof(b, jb)
            if (r0 < c0) cycle
            q = q + 1
            ri(q) = r0
            rj(q) = c0
            rv(q) = kval(e)
            if (ja > 0) then
              ca = i1 - cbody%rot_dof(1, ja) + 1
              rv(q) = rv(q)*cbody%rot(ca, a, ja)
            end if
            if (jb > 0) then
              cb = j1 - cbody%rot_dof(1, jb) + 1
              rv(q) = rv(q)*cbody%rot(cb, b, jb)
            end if
          end do
        end do
      end do
    end do
    ri = ri(1:q)
    rj = rj(1:q)
    rv = rv(1:q)
  end subroutine rotated_triplets

  !> B_a's part on the prescribed DOFs, B_a,d u_d (cbody%bfix), for the body's current
  !! u_fixed (a load step changes it): each row's entries on prescribed DOFs, in row order.
  subroutine prescribed_part(itf, sys, cbody)
    type(interface_t), intent(in) :: itf           !< the contact rows of all pairs
    type(body_system_t), intent(in) :: sys         !< the body's DOF map and u_fixed
    type(body_condensed_t), intent(inout) :: cbody !< its rows (slots); gets bfix
    integer :: i, e, row, side
    do i = 1, cbody%m
      row = slot_row(cbody%slots(i), itf%m)
      side = slot_side(cbody%slots(i), itf%m)
      cbody%bfix(i) = 0.0_wp
      associate (b => itf%b(side))
        do e = b%ptr(row), b%ptr(row + 1) - 1
          if (b%val(e) == 0.0_wp) cycle
          if (sys%free_of(b%dof(e)) /= 0) cycle
          cbody%bfix(i) = cbody%bfix(i) + b%val(e)*sys%u_fixed(b%dof(e))
        end do
      end associate
    end do
  end subroutine prescribed_part

  !> Factorize K_a with the interface DOFs ordered last, by the factor the deck's setting
  !! names (factorization%new_factor). ordering='nd' (CHOLMOD) orders the other DOFs by
  !! geometric nested dissection of the body's grid (module ordering); its time is part of
  !! t_factor. With MUMPS (collective over `comm`) each rank gives its share of K_a's cells
  !! as triplets irn, jcn, kval (assembly%cell_triplets); the others give the whole K_a (sys).
  subroutine factor_body(fc, itf, a, msh, sys, cbody, err, comm, irn, jcn, kval)
    type(factor_cfg_t), intent(in) :: fc             !< factorization and ordering
    type(interface_t), intent(in) :: itf             !< the contact rows of all pairs
    integer, intent(in) :: a                         !< body number
    type(mesh_t), intent(in) :: msh                  !< mesh of body a
    type(body_system_t), intent(in) :: sys           !< assembled system of body a
    type(body_condensed_t), intent(inout) :: cbody   !< receives the factorization
    type(error_t), intent(out) :: err                !< the failure (see the factor's factorize), if any
    integer, intent(in), optional :: comm            !< MUMPS: the body's group of ranks
    integer, intent(in), optional :: irn(:), jcn(:)  !< MUMPS: this rank's entries of K_a, 1-based
    real(wp), intent(in), optional :: kval(:)        !< MUMPS: their values [stress]
    integer, allocatable :: perm(:), ri(:), rj(:)
    real(wp), allocatable :: kr(:), rv(:)
    real(wp) :: t0

    t0 = wtime()
    call interface_dofs(itf, a, sys, cbody)
    if (allocated(cbody%fac)) then
      call cbody%fac%free()
      deallocate (cbody%fac)
    end if
    call new_factor(fc, a, cbody%fac, comm)
    if (cbody%nrot > 0 .and. .not. present(irn)) call rotated_values(sys, cbody, kr)
    if (present(irn)) then
      if (cbody%nrot > 0) then
        call rotated_triplets(cbody, sys%n, irn, jcn, kval, ri, rj, rv)
        call cbody%fac%factorize(sys%n, cbody%idx, err, irn=ri, jcn=rj, tval=rv)
      else
        call cbody%fac%factorize(sys%n, cbody%idx, err, irn=irn, jcn=jcn, tval=kval)
      end if
    else if (cbody%fac%wants_interior_order()) then
      if (msh%structured) then
        call grid_dissection(msh%nx, msh%ny, sys%free_of, sys%n, cbody%idx, perm, err)
      else
        call coordinate_bisection(msh%xy, sys%free_of, sys%dof_of, sys%colptr, sys%rowind, cbody%idx, perm, err)
      end if
      if (err%failed()) then
        cbody%t_factor = wtime() - t0
        return
      end if
      if (cbody%nrot > 0) then
        call cbody%fac%factorize(sys%n, cbody%idx, err, sys%colptr, sys%rowind, kr, interior_perm=perm)
      else
        call cbody%fac%factorize(sys%n, cbody%idx, err, sys%colptr, sys%rowind, sys%val, interior_perm=perm)
      end if
    else if (cbody%nrot > 0) then
      call cbody%fac%factorize(sys%n, cbody%idx, err, sys%colptr, sys%rowind, kr)
    else
      call cbody%fac%factorize(sys%n, cbody%idx, err, sys%colptr, sys%rowind, sys%val)
    end if
    cbody%t_factor = wtime() - t0
  end subroutine factor_body

  !> Form F_a and b_a (and u0 = K_a^-1 f_a, unless the factor is distributed) from the
  !! factorization: F_a = B_a (K_a^-1) B_a' on the interface DOFs by the factor's
  !! rows_flexibility, its rank (flex_finish), b_a by one solve (interface_load; an OpenMP
  !! task beside the flexibility when that only reads the factor). Collective with MUMPS
  !! (flex and b on the host).
  subroutine condense_body(sys, cbody, err)
    type(body_system_t), intent(in) :: sys           !< assembled system of the body
    type(body_condensed_t), intent(inout) :: cbody   !< factorized body; receives flex, b, u0
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp) :: t0
    integer :: st
    type(error_t) :: err_load
    logical :: beside
    integer(c_int) :: tiles
    t0 = wtime()
    beside = .false.
    if (cbody%fac%holds_result()) then
      if (allocated(cbody%flex)) deallocate (cbody%flex)
      allocate (cbody%flex(cbody%m, cbody%m), stat=st)
      if (st /= 0) then
        call err%set(ERR_MEMORY, 'out of memory for the interface flexibility')
        return
      end if
      if (cbody%m > 0) cbody%flex = 0.0_wp
      if (cbody%m > 0 .and. size(cbody%idx) > 0) then
        ! b_a's solve beside the flexibility when that only reads the factor: a thread the
        ! body loop leaves idle takes it (else this one, at the wait)
        beside = cbody%fac%flexibility_beside_solve(cbody%idx)
        if (beside) then
          !$omp task default(shared) private(tiles)
          tiles = tiles_pause()
          call interface_load(sys, cbody, err_load)
          call tiles_resume(tiles)
          !$omp end task
        end if
        call cbody%fac%rows_flexibility(cbody%idx, cbody%bptr, cbody%bpos, cbody%bval, cbody%flex, err)
      end if
      if (.not. err%failed()) call flex_finish(cbody)
      !$omp taskwait
      if (err%failed()) return
    end if
    if (beside) then
      err = err_load
    else
      call interface_load(sys, cbody, err)
    end if
    cbody%t_condense = wtime() - t0
  end subroutine condense_body

  !> b_a = B_a K_a^-1 f_a + B_a,d u_d for the body's current loads (one solve, collective
  !! with MUMPS; b on the host), keeping u0 = K_a^-1 f_a unless the factor is distributed.
  !! B_a,d u_d (bfix) is the caller's (interface_dofs, prescribed_part).
  subroutine interface_load(sys, cbody, err)
    type(body_system_t), intent(in) :: sys           !< the body's loads
    type(body_condensed_t), intent(inout) :: cbody   !< factorized body; receives b (and u0)
    type(error_t), intent(out) :: err                !< the solve's failure, if any
    real(wp), allocatable :: u0(:)
    if (.not. allocated(cbody%b)) allocate (cbody%b(cbody%m))
    if (size(cbody%b) /= cbody%m) then
      deallocate (cbody%b)
      allocate (cbody%b(cbody%m))
    end if
    if (cbody%fac%holds_result()) then
      u0 = sys%f
      call to_global(cbody, u0, inverse=.true.)
    else
      allocate (u0(0))
    end if
    call cbody%fac%solve(u0, err)
    if (err%failed()) return
    if (cbody%fac%holds_result()) call apply_b(cbody, u0, cbody%b)
    if (.not. cbody%fac%distributed) call move_alloc(u0, cbody%u0)
  end subroutine interface_load

  !> F_a = B_a X B_a' from X = (K_a^-1) on the interface DOFs cbody%idx (factorization's
  !! flex_product), then its numerical rank and proximal weight (flex_finish).
  subroutine flex_from_x(cbody, x)
    type(body_condensed_t), intent(inout) :: cbody   !< body with its rows; receives flex, rank, prox
    real(wp), intent(in) :: x(:, :)                  !< (k,k) (K_a^-1) on cbody%idx [length/force]
    if (allocated(cbody%flex)) deallocate (cbody%flex)
    allocate (cbody%flex(cbody%m, cbody%m))
    call flex_product(x, cbody%bptr, cbody%bpos, cbody%bval, cbody%flex)
    call flex_finish(cbody)
  end subroutine flex_from_x

  !> F_a's numerical rank, kernel or range, and proximal weight (flex_rank), unless every row
  !! selects its own DOF (F_a then positive definite).
  subroutine flex_finish(cbody)
    type(body_condensed_t), intent(inout) :: cbody   !< body with flex; receives rank, prox, kern, rng
    cbody%rank = cbody%m
    cbody%prox = 0.0_wp
    if (allocated(cbody%kern)) deallocate (cbody%kern)
    if (allocated(cbody%rng)) deallocate (cbody%rng)
    if (cbody%m > 0 .and. .not. selection_rows(cbody)) call flex_rank(cbody)
  end subroutine flex_finish

  !> True when every row of B_a picks one DOF, each a different one (F_a is then a principal
  !! block of K_a^-1 up to signs, positive definite).
  pure logical function selection_rows(cbody)
    type(body_condensed_t), intent(in) :: cbody
    selection_rows = size(cbody%idx) == cbody%m .and. size(cbody%bpos) == cbody%m
  end function selection_rows

  !> The numerical rank of F_a by Cholesky with complete pivoting (pivots below
  !! 1e-10 max diag stop it), unless a plain Cholesky factor and its condition estimate show
  !! full rank with a wide margin; when it is rank deficient, `prox` is a hundredth of its
  !! largest diagonal entry and `kern` an orthonormal basis of the kernel:
  !! the eigenvectors of the m - rank smallest eigenvalues (LAPACK dsyevr, once, O(m^3)),
  !! and of every further eigenvalue up to NEAR_KERNEL max diag (rank lowered to match).
  !! A graded master coarser than the slave in part also has rows that are only nearly
  !! dependent (a slave segment over a sliver of a master segment): eigenvalues of 1e-11 to
  !! 1e-4 max diag, above the pivot tolerance. Along them the body is all but rigid, the
  !! harmonic operator (about 2 F_a there) moves the obstacles by less than the inner
  !! tolerance resolves, and the forces stall away from the monolithic ones (a floating
  !! punch on a coated block: residual 1.1e-4 at 2.4e-9 max diag); pinned to the partner's
  !! forces like the kernel they converge. Up to 1e-6: from 1e-5 on the stall is below
  !! 100 tol and pinning costs outer iterations (it converges at the relaxation's rate).
  !! F_a = 0 (all its contact DOFs prescribed): rank 0, no `kern` (the proximal term is then
  !! the other body's F).
  subroutine flex_rank(cbody)
    type(body_condensed_t), intent(inout) :: cbody
    real(wp), allocatable :: f(:, :), work(:), ev(:), z(:, :), lsh(:, :)
    integer, allocatable :: piv(:), isuppz(:), iwork(:)
    integer :: lapinfo, r, lwork, liwork, k, nfound, nnear, shinfo
    integer(c_int) :: tiles
    logical :: sub
    logical :: halting(size(ieee_usual)), converged
    real(wp) :: dmax, rcond, anorm
    integer :: i
    dmax = 0.0_wp
    do i = 1, cbody%m
      dmax = max(dmax, cbody%flex(i, i))
    end do
    if (.not. dmax > 0.0_wp) then
      ! every contact DOF of the body is prescribed (a foundation drawn as a body): F_a = 0,
      ! its kernel is everything, and the proximal term alone (the other body's F) carries
      ! its subproblem: the other body then solves the obstacle problem against it
      cbody%rank = 0
      cbody%prox = 1.0_wp
      return
    end if
    if (2*size(cbody%idx) <= cbody%m) then
      call low_rank_range(cbody, dmax)
      return
    end if
    allocate (f(cbody%m, cbody%m), work(3*cbody%m), piv(cbody%m))
    ! The usual F_a is plainly of full rank, which the blocked Cholesky factor and LAPACK's
    ! condition estimate show at half the cost of the pivoted factor: lambda_min(F_a) >=
    ! 1 / |F_a^-1|_1, estimated, at least 1e4 times the pivot tolerance below (no estimate is
    ! that far off). Anything else is decided by the pivoted factor, as before.
    if (cbody%m >= SUBSPACE_MIN .and. size(cbody%idx) < cbody%m) then
      ! more rows than DOFs (a 3D frictional master: three rows a slave node): singular by
      ! its shape, of rank at most its DOFs; the inertia count below decides the kernel
      ! (neither the plain nor the pivoted factor is needed to know that)
      r = size(cbody%idx)
    else
      f = cbody%flex
      call dpotrf_tiles('L', cbody%m, f, cbody%m, lapinfo)
      if (lapinfo == 0) then
        anorm = maxval(sum(abs(cbody%flex), dim=1))
        call dpocon('L', cbody%m, f, cbody%m, anorm, rcond, work, piv, lapinfo)
        if (lapinfo == 0 .and. rcond*anorm >= 1.0e-6_wp*dmax) then
          cbody%rank = cbody%m
          return
        end if
      end if
      f = cbody%flex
      call dpstrf('L', cbody%m, f, cbody%m, piv, r, 1.0e-10_wp*dmax, work, lapinfo)
      if (lapinfo < 0) return
    end if
    cbody%rank = r
    if (r == cbody%m) return
    cbody%prox = 1.0e-2_wp*dmax
    ! the eigenvectors of the m - r smallest eigenvalues only (the tridiagonal reduction is
    ! the O(m^3) part: a tenth of the time of all m eigenvectors)
    f = cbody%flex
    k = cbody%m - r
    allocate (ev(cbody%m), isuppz(2*cbody%m), iwork(1))
    allocate (z(cbody%m, k))
    ! dsyevr starts by testing that IEEE infinities and NaNs are safe, by making some
    ! (LAPACK's ILAENV/IEEECK, the workspace query too): no floating-point trap while it runs
    ! (the checked build sets them)
    call ieee_get_halting_mode(ieee_usual, halting)
    call ieee_set_halting_mode(ieee_usual, .false.)
    call dsyevr('V', 'I', 'L', cbody%m, f, cbody%m, 0.0_wp, 0.0_wp, 1, k, 0.0_wp, nfound, ev, z, cbody%m, isuppz, &
                work, -1, iwork, -1, lapinfo)
    lwork = max(26*cbody%m, int(work(1)))
    liwork = max(10*cbody%m, iwork(1))
    deallocate (work, iwork)
    allocate (work(lwork), iwork(liwork))
    deallocate (f)   ! (made again for dsyevr below, if it is needed)
    ! the subspace iteration's block of 2k vectors (at least k + 32) fits (smallest_eigenvectors)
    sub = cbody%m >= SUBSPACE_MIN .and. max(2*k, k + 32) < cbody%m
    ! how many eigenvalues lie below NEAR_KERNEL max diag: the inertia of F_a - NEAR_KERNEL
    ! max diag I (Sylvester), its negative eigenvalues those of D in L D L' (a quarter of the
    ! tridiagonal reduction that counting by dsyevr took)
    if (sub) then
      ! the count and the shifted factor of the subspace iteration below need only F_a: two
      ! tasks (a thread the body loop leaves idle takes one)
      !$omp taskgroup
      !$omp task default(shared) private(tiles)
      tiles = tiles_pause()
      nnear = count_below(cbody%flex, NEAR_KERNEL*dmax)
      call tiles_resume(tiles)
      !$omp end task
      call shifted_factor(cbody%flex, dmax, lsh, shinfo)
      !$omp end taskgroup
    else
      nnear = count_below(cbody%flex, NEAR_KERNEL*dmax)
    end if
    if (nnear > k) then
      k = nnear
      deallocate (z)
      allocate (z(cbody%m, k))
    end if
    lapinfo = 1
    if (sub) then
      ! a large F_a: its k smallest eigenvectors by subspace iteration, a fraction of the
      ! tridiagonal reduction's time (LAPACK's own eigensolver when that does not converge)
      converged = .false.
      if (shinfo == 0) call smallest_eigenvectors(cbody%flex, k, dmax, z, converged, lsh)
      if (converged) then
        lapinfo = 0
        nfound = k
      end if
    end if
    if (lapinfo /= 0) then
      f = cbody%flex
      call dsyevr('V', 'I', 'L', cbody%m, f, cbody%m, 0.0_wp, 0.0_wp, 1, k, 0.0_wp, nfound, ev, z, cbody%m, isuppz, &
                  work, lwork, iwork, liwork, lapinfo)
    end if
    call ieee_set_halting_mode(ieee_usual, halting)
    ! no eigenvectors (dsyevr failed): robin_operators then uses the other body's F
    if (lapinfo == 0 .and. nfound == k) then
      cbody%kern = z
      cbody%rank = cbody%m - k
    end if

  contains

    !> The eigenvalues of the symmetric a below tau, by the inertia of a - tau I (LAPACK
    !! dsytrf: a 1x1 block of D counts when negative, a 2x2 block once when its determinant is
    !! negative, twice when its determinant is positive and its trace negative); -1 when the
    !! factorization fails (then no count).
    integer function count_below(a, tau) result(nneg)
      real(wp), intent(in) :: a(:, :), tau
      real(wp), allocatable :: s(:, :), w(:)
      integer, allocatable :: ipiv(:)
      integer :: n, j, info, lw
      real(wp) :: det
      n = size(a, 1)
      nneg = -1
      allocate (s, source=a)
      do j = 1, n
        s(j, j) = s(j, j) - tau
      end do
      allocate (ipiv(n), w(1))
      call dsytrf('L', n, s, n, ipiv, w, -1, info)
      lw = max(1, int(w(1)))
      deallocate (w)
      allocate (w(lw))
      call dsytrf('L', n, s, n, ipiv, w, lw, info)
      if (info < 0) return
      nneg = 0
      j = 1
      do while (j <= n)
        if (ipiv(j) > 0 .or. j == n) then
          if (s(j, j) < 0.0_wp) nneg = nneg + 1
          j = j + 1
        else
          det = s(j, j)*s(j + 1, j + 1) - s(j + 1, j)**2
          if (det < 0.0_wp) then
            nneg = nneg + 1
          else if (s(j, j) + s(j + 1, j + 1) < 0.0_wp) then
            nneg = nneg + 2
          end if
          j = j + 2
        end if
      end do
    end function count_below

  end subroutine flex_rank

  !> The eigenvectors of the k smallest eigenvalues of the symmetric positive semidefinite
  !! f (m x m, both triangles) by subspace iteration with (f + sigma I)^-1, sigma = 1e-10
  !! dmax (its Cholesky factor, O(m^3/3)), on b = max(2k, k + 32) vectors from a fixed
  !! start (the same bits every run), orthonormalized after each solve (QR), and the
  !! Rayleigh-Ritz pairs from the third solve on: done when every one of the k has
  !! |f z - theta z| <= 1e-12 dmax (the eigenvalues between k and b converge with them,
  !! at the ratio (lambda_i + sigma) / (lambda_b+1 + sigma) a solve). converged
  !! false (z undefined; the caller falls back to LAPACK's eigensolver) when the factor
  !! fails, b reaches m, or 12 solves do not converge.
  subroutine smallest_eigenvectors(f, k, dmax, z, converged, lsh)
    real(wp), intent(in) :: f(:, :)
    integer, intent(in) :: k
    real(wp), intent(in) :: dmax
    real(wp), allocatable, intent(out) :: z(:, :)
    logical, intent(out) :: converged   !< the k vectors found (else z undefined)
    real(wp), allocatable, intent(inout), optional :: lsh(:, :)   !< shifted_factor's factor, taken (else made here)
    integer, parameter :: MAX_SOLVES = 12
    real(wp), allocatable :: l(:, :), v(:, :), fv(:, :), hs(:, :), ev(:), work(:), tau(:)
    integer :: m, b, i, j, it, info, lwork, h, info2
    integer(c_long) :: ntiles
    integer(c_int) :: tiles
    real(wp) :: res
    m = size(f, 1)
    b = max(2*k, k + 32)
    converged = .false.
    if (k < 1 .or. b >= m) return
    if (present(lsh)) then
      call move_alloc(lsh, l)
    else
      call shifted_factor(f, dmax, l, info)
      if (info /= 0) return
    end if
    allocate (v(m, b), fv(m, b), hs(b, b), ev(b), tau(b), work(1))
    ! a fixed start of full rank: cos of integer multiples (no random state)
    do j = 1, b
      do i = 1, m
        v(i, j) = cos(real(i, wp)*real(j, wp)*0.7548776662466927_wp + real(j, wp))
      end do
    end do
    call dgeqrf(m, b, v, m, tau, work, -1, info)
    lwork = max(b, int(work(1)))
    call dsyev('V', 'L', b, hs, b, ev, work, -1, info)
    lwork = max(lwork, int(work(1)), 64*b)
    deallocate (work)
    allocate (work(lwork))
    if (.not. orthonormal()) return
    do it = 1, MAX_SOLVES
      ! the columns in two halves, two tasks (the same numbers for any thread count)
      h = b/2
      !$omp taskgroup
      !$omp task default(shared) private(tiles)
      tiles = tiles_pause()
      call dpotrs('L', m, h, l, m, v, m, info2)
      call tiles_resume(tiles)
      !$omp end task
      call dpotrs('L', m, b - h, l, m, v(1, h + 1), m, info)
      !$omp end taskgroup
      if (info /= 0 .or. info2 /= 0) return
      if (.not. orthonormal()) return
      if (it < 3) cycle
      ! Rayleigh-Ritz: hs = v' f v, its eigenpairs, z = v y (ascending)
      call tiles_begin()
      call dgemm('N', 'N', m, b, m, 1.0_wp, f, m, v, m, 0.0_wp, fv, m)
      ntiles = tiles_end()
      call dgemm('T', 'N', b, b, m, 1.0_wp, v, m, fv, m, 0.0_wp, hs, b)
      hs = 0.5_wp*(hs + transpose(hs))
      call dsyev('V', 'L', b, hs, b, ev, work, lwork, info)
      if (info /= 0) return
      if (allocated(z)) deallocate (z)
      allocate (z(m, k))
      call dgemm('N', 'N', m, k, b, 1.0_wp, v, m, hs, b, 0.0_wp, z, m)
      ! residuals |f z_i - theta_i z_i| = |fv y_i - theta_i z_i|
      res = 0.0_wp
      do i = 1, k
        res = max(res, norm2(matmul(fv, hs(:, i)) - ev(i)*z(:, i)))
      end do
      if (res <= 1.0e-12_wp*dmax) then
        converged = .true.
        return
      end if
      v = matmul(v, hs)
    end do

  contains

    !> v's columns orthonormalized (QR); false when LAPACK fails.
    logical function orthonormal() result(yes)
      call dgeqrf(m, b, v, m, tau, work, lwork, info)
      yes = info == 0
      if (.not. yes) return
      call dorgqr(m, b, b, v, m, tau, work, lwork, info)
      yes = info == 0
    end function orthonormal

  end subroutine smallest_eigenvectors

  !> The Cholesky factor (lower) of f + 1e-10 dmax I, the shift of smallest_eigenvectors'
  !! inverse iteration; info /= 0: none.
  subroutine shifted_factor(f, dmax, l, info)
    real(wp), intent(in) :: f(:, :)
    real(wp), intent(in) :: dmax
    real(wp), allocatable, intent(out) :: l(:, :)
    integer, intent(out) :: info
    integer :: i, m
    m = size(f, 1)
    allocate (l(m, m))
    l = f
    do i = 1, m
      l(i, i) = l(i, i) + 1.0e-10_wp*dmax
    end do
    call dpotrf_tiles('L', m, l, m, info)
  end subroutine shifted_factor

  !> F_a = B_a X B_a' from k <= m/2 interface DOFs (a master surface at least twice as
  !! coarse as its slave): its rank is at most k and its range lies in that of B_a, so its
  !! eigenpairs are those of Q' F_a Q (k x k) for Q an orthonormal basis of B_a's columns
  !! (QR), O(m^2 k), where the m x m eigenproblem of flex_rank costs O(m^3) for m - k kernel
  !! vectors it does not need (a 40^3 box on a 3^3 one: 1681 rows, 16 DOFs). The range basis
  !! is Q times the eigenvectors of the eigenvalues above NEAR_KERNEL max diag; every other
  !! direction is kernel, as in flex_rank. LAPACK failing: rank k, no basis (robin_operators
  !! then uses the other body's F).
  subroutine low_rank_range(cbody, dmax)
    type(body_condensed_t), intent(inout) :: cbody
    real(wp), intent(in) :: dmax                   !< max diag F_a (> 0)
    real(wp), allocatable :: q(:, :), fq(:, :), s(:, :), ev(:), work(:), tau(:)
    integer, allocatable :: iwork(:)
    integer :: m, k, i, e, r, lapinfo, lwork, liwork
    logical :: halting(size(ieee_usual))
    m = cbody%m
    k = size(cbody%idx)
    cbody%prox = 1.0e-2_wp*dmax
    cbody%rank = k
    allocate (q(m, k), tau(k), work(1), fq(m, k), s(k, k), ev(k), iwork(1))
    q = 0.0_wp
    do i = 1, m
      do e = cbody%bptr(i), cbody%bptr(i + 1) - 1
        q(i, cbody%bpos(e)) = q(i, cbody%bpos(e)) + cbody%bval(e)
      end do
    end do
    call dgeqrf(m, k, q, m, tau, work, -1, lapinfo)
    lwork = max(k, int(work(1)))
    deallocate (work)
    allocate (work(lwork))
    call dgeqrf(m, k, q, m, tau, work, lwork, lapinfo)
    if (lapinfo /= 0) return
    call dorgqr(m, k, k, q, m, tau, work, lwork, lapinfo)
    if (lapinfo /= 0) return
    call dgemm('N', 'N', m, k, m, 1.0_wp, cbody%flex, m, q, m, 0.0_wp, fq, m)
    call dgemm('T', 'N', k, k, m, 1.0_wp, q, m, fq, m, 0.0_wp, s, k)
    s = 0.5_wp*(s + transpose(s))
    ! no floating-point trap in LAPACK's IEEE tests (as in flex_rank)
    call ieee_get_halting_mode(ieee_usual, halting)
    call ieee_set_halting_mode(ieee_usual, .false.)
    call dsyevd('V', 'L', k, s, k, ev, work, -1, iwork, -1, lapinfo)
    lwork = max(1 + 6*k + 2*k*k, int(work(1)))
    liwork = max(3 + 5*k, iwork(1))
    deallocate (work, iwork)
    allocate (work(lwork), iwork(liwork))
    call dsyevd('V', 'L', k, s, k, ev, work, lwork, iwork, liwork, lapinfo)
    call ieee_set_halting_mode(ieee_usual, halting)
    if (lapinfo /= 0) return
    ! ascending: the last r eigenvalues are above the near-kernel level
    r = count(ev > NEAR_KERNEL*dmax)
    allocate (cbody%rng(m, r))
    if (r > 0) call dgemm('N', 'N', m, r, k, 1.0_wp, q, m, s(:, k - r + 1:), k, 0.0_wp, cbody%rng, m)
    cbody%rank = r
  end subroutine low_rank_range

  !> w(m) = B_a u: the rows on the free displacements u (n, in the body's contact frames:
  !! `to_global` with inverse turns a global one into them) plus the part on prescribed DOFs.
  subroutine apply_b(cbody, u, w)
    type(body_condensed_t), intent(in) :: cbody      !< condensed body
    real(wp), intent(in) :: u(:)                     !< (n) free displacements [length]
    real(wp), intent(out) :: w(:)                    !< (m) B_a u [length]
    integer :: i, e
    do i = 1, cbody%m
      w(i) = 0.0_wp
      do e = cbody%bptr(i), cbody%bptr(i + 1) - 1
        w(i) = w(i) + cbody%bval(e)*u(cbody%idx(cbody%bpos(e)))
      end do
      w(i) = w(i) + cbody%bfix(i)
    end do
  end subroutine apply_b

  !> r(n) = B_a' lam: scatter the interface forces onto the normal DOFs (in the body's
  !! contact frames: `to_global` turns r into the global frame).
  subroutine apply_bt(cbody, lam, r)
    type(body_condensed_t), intent(in) :: cbody      !< condensed body
    real(wp), intent(in) :: lam(:)                   !< (m) interface forces [force]
    real(wp), intent(inout) :: r(:)                  !< (n) r += B_a' lam
    integer :: i, e
    do i = 1, cbody%m
      do e = cbody%bptr(i), cbody%bptr(i + 1) - 1
        r(cbody%idx(cbody%bpos(e))) = r(cbody%idx(cbody%bpos(e))) + cbody%bval(e)*lam(i)
      end do
    end do
  end subroutine apply_bt

  !> u_free = K_a^-1 (f_a - B_a' lam): the body's displacement under its load and the
  !! contact forces lam, by one solve: u0 - K_a^-1 B_a' lam when condensation kept u0, else
  !! K_a^-1 (f_a - B_a' lam) (a distributed factor: collective, u_free on the host).
  !! err: the solve failed (u_free is then not set).
  subroutine recover_displacement(sys, cbody, lam, u_free, err)
    type(body_system_t), intent(in) :: sys           !< assembled system
    type(body_condensed_t), intent(inout) :: cbody   !< factorized body
    real(wp), intent(in) :: lam(:)                   !< (m) contact force on this body [force]
    real(wp), intent(inout) :: u_free(:)             !< (n) displacement at free DOFs [length] (host)
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp), allocatable :: r(:)
    if (allocated(cbody%u0)) then
      allocate (r(sys%n))
      r = 0.0_wp
      call apply_bt(cbody, lam, r)
      call cbody%fac%solve(r, err)
      if (err%failed()) return
      u_free = cbody%u0 - r
      call to_global(cbody, u_free)
    else
      if (cbody%fac%holds_result()) then
        r = sys%f
        call to_global(cbody, r, inverse=.true.)
        r = -r
        call apply_bt(cbody, lam, r)
        r = -r
      else
        allocate (r(0))
      end if
      call cbody%fac%solve(r, err)
      if (cbody%fac%holds_result() .and. .not. err%failed()) then
        u_free = r
        call to_global(cbody, u_free)
      end if
    end if
  end subroutine recover_displacement

end module condense
