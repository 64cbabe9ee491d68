!> Contact frames (condense `contact_frames`): a row that acts on one node alone, on two or
!! more of its components, all of them free, turns that node into the row's frame
!! R = [n, t1, t2], and the factorization sees T'K T. Checked on a synthetic solid body of
!! four nodes (one with a prescribed component) and four rows, against dense references
!! computed here:
!!  - which nodes get a frame: the one of a row on all three components of a free node; not
!!    a node under a row of one component, nor one with a prescribed component, nor the
!!    nodes of a row over two nodes; R orthonormal (R'R = I to 1e-15) with n as its first
!!    column, in the plane and in space (frame_of_normal);
!!  - B T: the rewritten rows equal the dense product to 1e-14, the defining row touches
!!    one DOF, with |D n| exactly;
!!  - T'K T from the CSC values (rotated_values) and from the lower-triangle triplets of K
!!    with duplicates split in two (rotated_triplets, summed): both the dense product to 1e-13;
!!  - to_global and its inverse: the identity to 1e-15.
program test_frames
  use kinds, only: wp
  use space, only: set_dimension, NCOMP, node_dof
  use assembly, only: body_system_t
  use condense, only: body_condensed_t, contact_frames, frame_of_normal, rotated_values, rotated_triplets, to_global
  use testing, only: report, report_le, test_summary, set_seed, urand, random_spd, identity
  implicit none (type, external)
  integer, parameter :: NNODE = 4
  type(body_system_t) :: sys
  type(body_condensed_t) :: cbody
  real(wp), allocatable :: k(:, :), b(:, :), t(:, :), kt(:, :), bt(:, :), kv(:), v(:), w(:), lo(:, :), rv(:)
  integer, allocatable :: irn(:), jcn(:), ri(:), rj(:)
  real(wp) :: n1(3), lmin, lmax, r2(2, 2), r3(3, 3), err
  integer :: n, i, j, e

  call set_seed(20261129)
  call set_dimension(3)
  ! free DOFs: every component of nodes 1-3, y and z of node 4 (its x prescribed)
  sys%ndof = NCOMP*NNODE
  allocate (sys%free_of(sys%ndof))
  sys%free_of = 0
  n = 0
  do i = 1, sys%ndof
    if (i == node_dof(4, 1)) cycle
    n = n + 1
    sys%free_of(i) = n
  end do
  sys%n = n
  sys%dof_of = pack([(i, i=1, sys%ndof)], sys%free_of > 0)
  allocate (k(n, n))
  call random_spd(n, 3.0_wp, k, lmin, lmax)
  ! K in CSC, both triangles, every entry (a dense pattern: each node's columns share it)
  allocate (sys%colptr(n + 1), sys%rowind(n*n), sys%val(n*n))
  sys%colptr(1) = 0
  do j = 1, n
    sys%rowind((j - 1)*n + 1:j*n) = [(i - 1, i=1, n)]
    sys%val((j - 1)*n + 1:j*n) = k(:, j)
    sys%colptr(j + 1) = j*n
  end do
  ! rows: 1 on node 1 (x, y, z: D n), 2 over nodes 1 and 3, 3 on node 2's y alone, 4 on
  ! node 4's y and z (its x prescribed)
  n1 = [urand(-1.0_wp, 1.0_wp), urand(-1.0_wp, 1.0_wp), urand(-1.0_wp, 1.0_wp)]
  n1 = n1/norm2(n1)
  allocate (b(4, n))
  b = 0.0_wp
  b(1, fr(1, 1):fr(1, 3)) = 0.37_wp*n1
  b(2, fr(1, 1):fr(1, 3)) = [0.2_wp, -0.5_wp, 0.1_wp]
  b(2, fr(3, 1):fr(3, 2)) = [0.3_wp, 0.7_wp]
  b(3, fr(2, 2)) = 1.1_wp
  b(4, fr(4, 2):fr(4, 3)) = [0.6_wp, -0.8_wp]
  cbody%m = 4
  cbody%n = n
  call rows_in(b, cbody)
  call contact_frames(sys, cbody)
  call report(cbody%nrot == 1, 'one node gets a frame (the one under row 1 alone), not the nodes of a '// &
              'two-node row, of a one-component row, or with a prescribed component', real(cbody%nrot, wp))
  if (cbody%nrot /= 1) call test_summary()
  call report(all(cbody%rot_dof(:, 1) == [fr(1, 1), fr(1, 2), fr(1, 3)]), 'the frame is node 1''s')
  r3 = cbody%rot(:, :, 1)
  call report_le(maxval(abs(matmul(transpose(r3), r3) - identity(3))), 1.0e-15_wp, 'R''R = I (space)')
  call report_le(maxval(abs(r3(:, 1) - n1)), 1.0e-15_wp, 'R''s first column is the row''s direction n')
  r2 = frame_of_normal([0.6_wp, -0.8_wp])
  call report_le(maxval(abs(matmul(transpose(r2), r2) - identity(2))) + maxval(abs(r2(:, 1) - [0.6_wp, -0.8_wp])), &
                 1.0e-15_wp, 'the plane frame: R''R = I, n first')
  ! T and the dense references
  allocate (t(n, n))
  t = identity(n)
  t(fr(1, 1):fr(1, 3), fr(1, 1):fr(1, 3)) = r3
  bt = matmul(b, t)
  kt = matmul(transpose(t), matmul(k, t))
  err = maxval(abs(rows_out(cbody) - bt))
  call report_le(err, 1.0e-14_wp, 'the rewritten rows are B T')
  call report(cbody%bptr(2) - cbody%bptr(1) == 1 .and. cbody%bval(cbody%bptr(1)) == norm2(0.37_wp*n1), &
              'the defining row touches one DOF, with |D n| exactly')
  call rotated_values(sys, cbody, kv)
  err = 0.0_wp
  do j = 1, n
    err = max(err, maxval(abs(kv(sys%colptr(j) + 1:sys%colptr(j + 1)) - kt(:, j))))
  end do
  call report_le(err/maxval(abs(k)), 1.0e-13_wp, 'T''K T from the CSC values')
  ! lower-triangle triplets, each entry split in two halves (duplicates to be summed)
  allocate (irn(0), jcn(0), rv(0))
  do j = 1, n
    do i = j, n
      irn = [irn, i, i]
      jcn = [jcn, j, j]
      rv = [rv, 0.25_wp*k(i, j), 0.75_wp*k(i, j)]
    end do
  end do
  call rotated_triplets(cbody, n, irn, jcn, rv, ri, rj, kv)
  allocate (lo(n, n))
  lo = 0.0_wp
  do e = 1, size(ri)
    lo(ri(e), rj(e)) = lo(ri(e), rj(e)) + kv(e)
  end do
  err = 0.0_wp
  do j = 1, n
    do i = 1, n
      if (i >= j) err = max(err, abs(lo(i, j) - kt(i, j)))
      if (i < j) err = max(err, abs(lo(i, j)))
    end do
  end do
  call report(all(ri >= rj), 'the rotated triplets lie on or below the diagonal')
  call report_le(err/maxval(abs(k)), 1.0e-13_wp, 'T''K T from the lower-triangle triplets (summed)')
  v = [(urand(-1.0_wp, 1.0_wp), i=1, n)]
  w = v
  call to_global(cbody, w)
  call report_le(maxval(abs(w - matmul(t, v))), 1.0e-15_wp, 'to_global is T v')
  call to_global(cbody, w, inverse=.true.)
  call report_le(maxval(abs(w - v)), 1.0e-15_wp, 'and its inverse T''')
  call test_summary()

contains

  !> The free DOF of node nd's component c.
  integer function fr(nd, c)
    integer, intent(in) :: nd, c
    fr = sys%free_of(node_dof(nd, c))
  end function fr

  !> The condensed body's rows from a dense B (its non-zero entries, idx in first-touch order).
  subroutine rows_in(bd, cbody)
    real(wp), intent(in) :: bd(:, :)
    type(body_condensed_t), intent(inout) :: cbody
    integer :: ii, jj, kk, ne
    integer, allocatable :: pos(:)
    allocate (pos(size(bd, 2)), cbody%idx(0), cbody%bptr(size(bd, 1) + 1), cbody%bpos(0), cbody%bval(0))
    pos = 0
    kk = 0
    ne = 0
    cbody%bptr(1) = 1
    do ii = 1, size(bd, 1)
      do jj = 1, size(bd, 2)
        if (bd(ii, jj) == 0.0_wp) cycle
        if (pos(jj) == 0) then
          kk = kk + 1
          cbody%idx = [cbody%idx, jj]
          pos(jj) = kk
        end if
        ne = ne + 1
        cbody%bpos = [cbody%bpos, pos(jj)]
        cbody%bval = [cbody%bval, bd(ii, jj)]
      end do
      cbody%bptr(ii + 1) = ne + 1
    end do
  end subroutine rows_in

  !> The dense B of a condensed body's rows.
  function rows_out(cbody) result(bd)
    type(body_condensed_t), intent(in) :: cbody
    real(wp) :: bd(cbody%m, cbody%n)
    integer :: ii, ee
    bd = 0.0_wp
    do ii = 1, cbody%m
      do ee = cbody%bptr(ii), cbody%bptr(ii + 1) - 1
        bd(ii, cbody%idx(cbody%bpos(ee))) = bd(ii, cbody%idx(cbody%bpos(ee))) + cbody%bval(ee)
      end do
    end do
  end function rows_out

end program test_frames
