!> Unit test of module ordering (geometric nested dissection of a body's node grid) and
!! of its use as a given interior order in module cholesky (ORD_GIVEN) and in
!! condense's factor_body (ordering = 'nd').
!! Checks: the permutation is exactly the free DOFs not in `last`; both DOFs of a node
!! are adjacent; the top-level separator (the middle grid line across the longer side)
!! comes last; a real FE body factored with nd, METIS and AMD gives the same solution
!! (scaled residual) and the same interface flexibility from the trailing block;
!! invalid inputs are reported; two bodies condensed with 'nd' equal 'metis'; on general
!! meshes (a grid renumbered at random, interior nodes moved: structured = .false.) the
!! coordinate bisection is a permutation with node DOFs together, factors to the METIS
!! solution and flexibility, with nnz(L) within 1.5x METIS's. Solid boxes (node_dissection,
!! ORD_NODES, what 'nd' gives a solid body): the order is a permutation of exactly the DOFs
!! not ordered last, each node's DOFs together, consecutive and in component order (checked
!! with the assembly's DOF map, and the check fails on a reversed order); the nodes found in
!! the pattern are the mesh's; the factor has the contact DOFs last in the given (scrambled)
!! order, solves K u = f and gives METIS's flexibility; on a 12^3 box its nnz(L) is within
!! 1.2x that of METIS on the DOF graph and below the natural order's; bad inputs reported.
!! One line per check; exits non-zero if any check fails.
program test_ordering
  use, intrinsic :: iso_fortran_env, only: output_unit
  use kinds, only: wp
  use config, only: deck_t, deck_init, body_cfg_t, traction_cfg_t, ELEM_Q1, ELEM_P1, ORDER_METIS, ORDER_ND, &
                    SIDE_RIGHT, SIDE_BOTTOM, SIDE_TOP, &
                    BC_FREE, BC_CLAMPED, BC_ROLLER, BC_CONTACT, factor_cfg_t
  use space, only: set_dimension, node_dof, dof_node
  use mesh, only: mesh_t, node_id
  use assembly, only: body_system_t, assemble_body, csc_matvec
  use supports, only: number_free_dofs
  use ordering, only: grid_dissection, coordinate_bisection, ND_LEAF_NODES, node_dissection, node_groups
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_METIS, ORD_AMD, ORD_GIVEN, ORD_NODES, ORD_AUTO, &
                      ORD_NATURAL
  use contact_interface, only: interface_t, build_interface
  use condense, only: body_condensed_t, factor_body, condense_body
  use factorization, only: cholmod_factor_t, factor_t, new_factor
  use clock, only: wtime
  use strings, only: i2s
  use testing, only: grid_mesh, report, report_le, test_summary, rectangle_body, structured_body, general_body, &
                     side_free_dofs, order_body, factor_ordered, error_parts, box_system
  use errors, only: error_t, ERR_NUMERICAL
  implicit none (type, external)

  real(wp), parameter :: eps = epsilon(1.0_wp)
  real(wp), parameter :: RES_TOL = 10.0_wp        ! scaled residual threshold
  real(wp), parameter :: FLEX_TOL = 1.0e-10_wp    ! relative flexibility agreement between orderings

  ! ---- permutation properties on assorted grids ----
  call check_perm('Q1 40x20, left clamped, bottom normal last', 40, 20, ELEM_Q1, &
                  [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE], SIDE_BOTTOM, 2)
  call check_perm('P1 1x1, all free, no last', 1, 1, ELEM_P1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], 0, 0)
  call check_perm('P1 1x7, bottom clamped, right x last', 1, 7, ELEM_P1, &
                  [BC_FREE, BC_CONTACT, BC_CLAMPED, BC_FREE], SIDE_RIGHT, 1)
  call check_perm('Q1 7x1, left clamped, top normal last', 7, 1, ELEM_Q1, &
                  [BC_CLAMPED, BC_FREE, BC_FREE, BC_CONTACT], SIDE_TOP, 2)
  call check_perm('P1 13x3, bottom roller, top normal last', 13, 3, ELEM_P1, &
                  [BC_FREE, BC_FREE, BC_ROLLER, BC_CONTACT], SIDE_TOP, 2)
  call check_perm('Q1 33x65, left clamped, right x last', 33, 65, ELEM_Q1, &
                  [BC_CLAMPED, BC_CONTACT, BC_FREE, BC_FREE], SIDE_RIGHT, 1)
  call check_perm('P1 64x64, top clamped, no last', 64, 64, ELEM_P1, &
                  [BC_FREE, BC_FREE, BC_FREE, BC_CLAMPED], 0, 0)

  ! ---- factor a real FE body with nd, METIS and AMD ----
  call check_factor('Q1 40x20', 40, 20, ELEM_Q1)
  call check_factor('P1 37x23', 37, 23, ELEM_P1)

  ! ---- invalid inputs ----
  call check_bad_input()

  ! ---- condense two bodies with ordering 'nd' vs 'metis' ----
  call check_condense()

  ! ---- general meshes: recursive coordinate bisection ----
  call check_general('general Q1 64x64, moved 0.3', 64, 64, ELEM_Q1, 0.3_wp, 7)
  call check_general('general P1 40x25, moved 0.2', 40, 25, ELEM_P1, 0.2_wp, 11)
  call check_general('general Q1 64x32, not moved', 64, 32, ELEM_Q1, 0.0_wp, 3)
  call check_general('general Q1 5x3, moved 0.3', 5, 3, ELEM_Q1, 0.3_wp, 5)
  call check_general_bad()

  ! ---- solid bodies: METIS on the node graph ----
  call set_dimension(3)
  call check_nodes_3d('box Q1 6x5x4, bottom clamped, left roller', 6, 5, 4, ELEM_Q1, &
                      [BC_ROLLER, BC_FREE, BC_CLAMPED, BC_CONTACT, BC_FREE, BC_FREE])
  call check_nodes_3d('box P1 3x4x5, bottom clamped, front roller', 3, 4, 5, ELEM_P1, &
                      [BC_FREE, BC_FREE, BC_CLAMPED, BC_CONTACT, BC_ROLLER, BC_FREE])
  call check_fill_3d(12)
  call check_nodes_bad()
  call set_dimension(2)

  ! ---- a large grid: ordering time at 1024 x 512 cells (printed, not asserted) ----
  call check_large()

  call test_summary()

contains

  !> Whether perm holds each free DOF 1..n not marked in is_last exactly once, and nothing else.
  logical function covers_rest(perm, is_last) result(ok)
    integer, intent(in) :: perm(:)        !< an interior order
    logical, intent(in) :: is_last(:)     !< (n) the DOFs ordered last by the caller
    integer, allocatable :: cnt(:)
    integer :: k
    ok = all(perm >= 1 .and. perm <= size(is_last))
    if (.not. ok) return
    allocate (cnt(size(is_last)))
    cnt = 0
    do k = 1, size(perm)
      cnt(perm(k)) = cnt(perm(k)) + 1
    end do
    ok = all(merge(cnt == 0, cnt == 1, is_last))
  end function covers_rest

  !> Whether both DOFs of a node are consecutive in perm, x then y, wherever both are in it.
  logical function node_dofs_adjacent(sys, perm, is_last) result(ok)
    type(body_system_t), intent(in) :: sys    !< the body's numbering
    integer, intent(in) :: perm(:)            !< an interior order (covers_rest)
    logical, intent(in) :: is_last(:)         !< the DOFs ordered last by the caller
    integer :: k, f, g
    ok = .true.
    do k = 1, size(perm)
      g = sys%dof_of(perm(k))
      if (mod(g, 2) == 1) then            ! an x DOF: its y DOF, if ordered, comes next
        f = sys%free_of(g + 1)
        if (f > 0) then
          if (.not. is_last(f)) then
            if (k == size(perm)) then
              ok = .false.
            else
              ok = ok .and. perm(k + 1) == f
            end if
          end if
        end if
      else                                ! a y DOF: its x DOF, if ordered, comes just before
        f = sys%free_of(g - 1)
        if (f > 0) then
          if (.not. is_last(f)) then
            if (k == 1) then
              ok = .false.
            else
              ok = ok .and. perm(k - 1) == f
            end if
          end if
        end if
      end if
    end do
  end function node_dofs_adjacent

  !> The ND permutation is exactly the free DOFs not in `last`, node DOFs adjacent,
  !! and the top-level separator line comes last.
  subroutine check_perm(name, nx, ny, elem, bcs, last_side, last_comp)
    character(len=*), intent(in) :: name
    integer, intent(in) :: nx, ny, elem, bcs(4), last_side, last_comp
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    integer, allocatable :: last(:), perm(:)
    logical, allocatable :: is_last(:)
    integer :: info, k, node, nsep, mid, i, j
    logical :: ok
    character(len=256) :: msg

    call structured_body(rectangle_body(nx, ny, elem, bcs), msh, sys, last)
    last = side_free_dofs(msh, sys, last_side, last_comp)
    call order_body(msh, sys, last, perm, info, msg)
    call report(info == 0, name//': nested dissection info = 0 '//trim(msg))
    if (info /= 0) return
    call report(size(perm) == sys%n - size(last), name//': size = n - size(last)')
    allocate (is_last(sys%n))
    is_last = .false.
    is_last(last) = .true.
    ok = covers_rest(perm, is_last)
    call report(ok, name//': a permutation of exactly the free non-interface DOFs')
    if (.not. ok) return
    call report(node_dofs_adjacent(sys, perm, is_last), name//': the two DOFs of a node are adjacent, x first')

    ! the top-level separator: the middle grid line across the longer side, last
    if ((nx + 1)*(ny + 1) >= ND_LEAF_NODES) then
      nsep = 0
      do k = 1, sys%n
        if (is_last(k)) cycle
        node = (sys%dof_of(k) + 1)/2
        i = mod(node - 1, nx + 1)
        j = (node - 1)/(nx + 1)
        if (nx >= ny) then
          if (i == nx/2) nsep = nsep + 1
        else
          if (j == ny/2) nsep = nsep + 1
        end if
      end do
      ok = nsep > 0
      do k = size(perm) - nsep + 1, size(perm)
        node = (sys%dof_of(perm(k)) + 1)/2
        if (nx >= ny) then
          mid = mod(node - 1, nx + 1)
          ok = ok .and. mid == nx/2
        else
          mid = (node - 1)/(nx + 1)
          ok = ok .and. mid == ny/2
        end if
      end do
      call report(ok, name//': the last DOFs are the middle grid line (top-level separator)')
    end if
  end subroutine check_perm

  !> With a body's factor in ch: its summary, one solve (the scaled residual checked) and the
  !! flexibility on `last` from the trailing block of L; then the factor is freed.
  subroutine solve_and_flex(ch, sys, last, sgn, tag, flex)
    type(chol_t), intent(inout) :: ch
    type(body_system_t), intent(in) :: sys
    integer, intent(in) :: last(:)
    real(wp), intent(in) :: sgn(:)
    character(len=*), intent(in) :: tag
    real(wp), intent(out) :: flex(:, :)
    real(wp), allocatable :: u(:), r(:)
    real(wp) :: res
    integer :: info
    logical :: used
    character(len=256) :: msg
    type(error_t) :: err
    write (output_unit, '(a)') '      '//ch%summary()
    allocate (r(sys%n))
    u = sys%f
    call ch%solve(u, err)
    call error_parts(err, info, msg)
    call csc_matvec(sys, u, r)
    res = maxval(abs(r - sys%f))/(real(sys%n, wp)*sys%k_norm*maxval(abs(u))*eps)
    call report(info == 0 .and. res <= RES_TOL, trim(tag)//': scaled residual |Ku-f|/(n|K||u|eps)', res, RES_TOL)
    call ch%flexibility(last, sgn, flex, err, used_block=used)
    call error_parts(err, info, msg)
    call report(info == 0 .and. used, trim(tag)//': flexibility from the trailing block of L '//trim(msg))
    call ch%free()
  end subroutine solve_and_flex

  !> Factor one body with METIS, AMD and nd, interface (bottom normal DOFs) last.
  subroutine check_factor(name, nx, ny, elem)
    character(len=*), intent(in) :: name
    integer, intent(in) :: nx, ny, elem
    character(len=*), parameter :: onames(3) = [character(len=5) :: 'metis', 'amd', 'nd']
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(chol_t) :: ch
    integer, allocatable :: last(:), perm(:)
    real(wp), allocatable :: sgn(:), flex(:, :, :)
    real(wp) :: d, nnz(3)
    integer :: o, info, m
    character(len=256) :: msg
    character(len=64) :: tag

    call structured_body(rectangle_body(nx, ny, elem, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE]), msh, sys, last)
    m = size(last)
    allocate (sgn(m), flex(m, m, 3))
    sgn = -1.0_wp
    nnz = 0.0_wp
    call order_body(msh, sys, last, perm, info, msg)
    call report(info == 0, name//': nested dissection ok '//trim(msg))
    if (info /= 0) return
    write (output_unit, '(a,i0,a,i0)') '      '//name//': n = ', sys%n, ', interface m = ', m
    do o = 1, 3
      tag = name//' '//trim(onames(o))
      call factor_ordered(ch, sys, o, last, perm, info, msg)
      call report(info == 0, trim(tag)//': factor info = 0 '//trim(msg))
      if (info /= 0) cycle
      nnz(o) = real(ch%nnz_factor, wp)
      call report(ch%interface_last_ok, trim(tag)//': interface DOFs ordered last, in the given order')
      call solve_and_flex(ch, sys, last, sgn, tag, flex(:, :, o))
    end do
    do o = 2, 3
      d = norm2(flex(:, :, o) - flex(:, :, 1))/norm2(flex(:, :, 1))
      call report_le(d, FLEX_TOL, name//' '//trim(onames(o))//': flexibility = METIS''s (relative)')
    end do
    write (output_unit, '(a,3(a,es10.3))') '      '//name//' nnz(L):', ' metis=', nnz(1), ' amd=', nnz(2), &
      ' nd=', nnz(3)
    call report(nnz(3) > 0.0_wp .and. nnz(3) <= 1.5_wp*nnz(1), name//': nnz(L) nd <= 1.5 x METIS', &
                nnz(3)/max(nnz(1), 1.0_wp), 1.5_wp)
  end subroutine check_factor

  !> Bad `last` and bad interior orders are reported, not crashed on.
  subroutine check_bad_input()
    type(mesh_t) :: msh, other
    type(body_system_t) :: sys
    type(chol_t) :: ch
    integer, allocatable :: last(:), perm(:), bad(:)
    integer :: info, n
    type(error_t) :: err
    character(len=256) :: msg

    call structured_body(rectangle_body(10, 6, ELEM_Q1, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE]), msh, sys, last)
    n = sys%n
    call order_body(msh, sys, [last, 0], perm, info, msg)
    call report(info == ERR_NUMERICAL .and. index(msg, 'interface DOF') > 0 .and. size(perm) == 0 .and. len_trim(msg) > 0, &
                'nested dissection: interface DOF 0 rejected: '//trim(msg))
    call order_body(msh, sys, [last, last(1)], perm, info, msg)
    call report(info == ERR_NUMERICAL .and. index(msg, 'interface DOF') > 0 .and. len_trim(msg) > 0, &
                'nested dissection: repeated interface DOF rejected: '//trim(msg))
    other%nx = 11
    other%ny = 6
    call order_body(other, sys, last, perm, info, msg)
    call report(info /= 0 .and. len_trim(msg) > 0, &
                'nested dissection: mesh of another size rejected: '//trim(msg))

    call order_body(msh, sys, last, perm, info, msg)
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, last=last)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'ORD_GIVEN without interior_perm: ERR_NUMERICAL: '//trim(msg))
    bad = perm(1:size(perm) - 1)
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, last=last, &
                   interior_perm=bad)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'interior_perm too short: ERR_NUMERICAL: '//trim(msg))
    bad = perm
    bad(2) = bad(1)
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, last=last, &
                   interior_perm=bad)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'interior_perm repeated entry: ERR_NUMERICAL: '//trim(msg))
    bad = perm
    bad(1) = last(1)
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, last=last, &
                   interior_perm=bad)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'interior_perm holds an interface DOF: ERR_NUMERICAL: '//trim(msg))
    ! the banded factorization ignores the ordering
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_BANDED, ORD_GIVEN, err)
    call error_parts(err, info, msg)
    call report(info == 0, 'banded with ORD_GIVEN (ordering ignored): info = 0')
    ! ORD_GIVEN without an interface: the whole order is given
    call order_body(msh, sys, [integer ::], perm, info, msg)
    call ch%factor(n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_GIVEN, err, interior_perm=perm)
    call error_parts(err, info, msg)
    call report(info == 0, 'ORD_GIVEN with no interface DOFs: info = 0 '//trim(msg))
    call ch%free()
  end subroutine check_bad_input

  !> Two bodies (the default scene's geometry, coarse) condensed with 'nd' and 'metis'.
  subroutine check_condense()
    type(deck_t) :: d
    type(mesh_t) :: msh(2)
    type(body_system_t) :: sys(2)
    type(interface_t) :: itf
    type(body_condensed_t) :: cbody(2, 2)
    type(traction_cfg_t) :: tr(2)
    character(len=5), parameter :: ords(2) = ['metis', 'nd   ']
    integer, parameter :: ord_codes(2) = [ORDER_METIS, ORDER_ND]
    integer :: a, o, info
    type(error_t) :: err
    character(len=256) :: msg
    real(wp) :: dflex, db

    call deck_init(d, 2, 1)
    d%body(1) = rectangle_body(30, 12, ELEM_Q1, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE])
    d%body(1)%y0 = 1.0_wp
    d%body(2) = rectangle_body(30, 10, ELEM_P1, [BC_CLAMPED, BC_FREE, BC_FREE, BC_CONTACT])
    d%body(2)%id = 2
    tr(1)%body = 1
    tr(1)%side = SIDE_TOP
    tr(1)%t0(1:2) = [0.0_wp, -3.0e6_wp]
    tr(2)%body = 2
    tr(2)%side = SIDE_BOTTOM
    tr(2)%t0(1:2) = [5.0e5_wp, 1.0e6_wp]
    do a = 1, 2
      call grid_mesh(msh(a), d%body(a))
      call assemble_body(msh(a), d%body(a), .true., tr, 2, sys(a), err)
      call error_parts(err, info, msg)
      if (info /= 0) error stop 'assembly failed: '//trim(msg)
    end do
    call build_interface(d%body, d%pair(1:1), .false., msh, sys, itf, err)
    call error_parts(err, info, msg)
    call report(info == 0 .and. itf%m > 0, 'two-body scene: interface built '//trim(msg))
    if (info /= 0) return
    do o = 1, 2
      d%solver%factor%ordering = ord_codes(o)
      do a = 1, 2
        call factor_body(d%solver%factor, itf, a, msh(a), sys(a), cbody(a, o), err)
        call error_parts(err, info, msg)
        call report(info == 0 .and. interface_last(cbody(a, o)), &
                    'factor_body ordering='''//trim(ords(o))//''', body '//i2s(a)//': ok, interface last '//trim(msg))
        if (info /= 0) return
        call condense_body(sys(a), cbody(a, o), err)
        call error_parts(err, info, msg)
        if (info /= 0) error stop 'condense_body failed: '//trim(msg)
      end do
    end do
    do a = 1, 2
      dflex = norm2(cbody(a, 2)%flex - cbody(a, 1)%flex)/max(norm2(cbody(a, 1)%flex), tiny(1.0_wp))
      db = norm2(cbody(a, 2)%b - cbody(a, 1)%b)/max(norm2(cbody(a, 1)%b), tiny(1.0_wp))
      call report_le(max(dflex, db), FLEX_TOL, 'body '//i2s(a)//': F_a and b_a with ''nd'' = with ''metis''')
      call cbody(a, 1)%fac%free()
      call cbody(a, 2)%fac%free()
    end do
  end subroutine check_condense

  !> A general body (renumbered, moved, structured = .false.): the coordinate bisection is
  !! a permutation of the free non-interface DOFs with node DOFs adjacent; factored with
  !! it, with METIS and with AMD the solutions and flexibilities agree; nnz(L) <= 1.5 x METIS.
  subroutine check_general(name, nx, ny, elem, perturb, seed)
    character(len=*), intent(in) :: name
    integer, intent(in) :: nx, ny, elem, seed
    real(wp), intent(in) :: perturb
    character(len=*), parameter :: onames(3) = [character(len=5) :: 'metis', 'amd', 'nd']
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(chol_t) :: ch
    integer, allocatable :: last(:), perm(:)
    logical, allocatable :: is_last(:)
    real(wp), allocatable :: u(:, :), r(:), sgn(:), flex(:, :, :)
    real(wp) :: res, d, nnz(3), t0, t_nd
    integer :: o, info, m
    type(error_t) :: err
    logical :: ok, used
    character(len=256) :: msg
    character(len=64) :: tag

    call general_body(rectangle_body(nx, ny, elem, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE]), perturb, seed, &
                      msh, sys, last)
    m = size(last)
    t0 = wtime()
    call order_body(msh, sys, last, perm, info, msg)
    t_nd = wtime() - t0
    call report(info == 0, name//': nested dissection info = 0 '//trim(msg))
    if (info /= 0) return
    allocate (is_last(sys%n))
    is_last = .false.
    is_last(last) = .true.
    ok = size(perm) == sys%n - m
    if (ok) ok = covers_rest(perm, is_last)
    call report(ok, name//': a permutation of exactly the free non-interface DOFs')
    if (.not. ok) return
    call report(node_dofs_adjacent(sys, perm, is_last), name//': the two DOFs of a node are adjacent, x first')

    allocate (u(sys%n, 3), r(sys%n), sgn(m), flex(m, m, 3))
    sgn = -1.0_wp
    nnz = 0.0_wp
    u = 0.0_wp
    do o = 1, 3
      tag = name//' '//trim(onames(o))
      call factor_ordered(ch, sys, o, last, perm, info, msg)
      call report(info == 0 .and. ch%interface_last_ok, trim(tag)//': factor ok, interface last '//trim(msg))
      if (info /= 0) cycle
      write (output_unit, '(a)') '      '//ch%summary()
      nnz(o) = real(ch%nnz_factor, wp)
      u(:, o) = sys%f
      call ch%solve(u(:, o), err)
      call error_parts(err, info, msg)
      call csc_matvec(sys, u(:, o), r)
      res = maxval(abs(r - sys%f))/(real(sys%n, wp)*sys%k_norm*maxval(abs(u(:, o)))*eps)
      call report(info == 0 .and. res <= RES_TOL, trim(tag)//': scaled residual |Ku-f|/(n|K||u|eps)', res, RES_TOL)
      if (m > 0) then
        call ch%flexibility(last, sgn, flex(:, :, o), err, used_block=used)
        call error_parts(err, info, msg)
        call report(info == 0 .and. used, trim(tag)//': flexibility from the trailing block of L')
      end if
      call ch%free()
    end do
    do o = 2, 3
      d = norm2(u(:, o) - u(:, 1))/norm2(u(:, 1))
      call report_le(d, 1.0e-12_wp, name//' '//trim(onames(o))//': solution = METIS''s (relative)')
      if (m > 0) then
        d = norm2(flex(:, :, o) - flex(:, :, 1))/norm2(flex(:, :, 1))
        call report_le(d, FLEX_TOL, name//' '//trim(onames(o))//': flexibility = METIS''s (relative)')
      end if
    end do
    write (output_unit, '(a,3(a,es10.3),a,f0.4,a)') '      '//name//' nnz(L):', ' metis=', nnz(1), ' amd=', nnz(2), &
      ' nd=', nnz(3), ' (nd ordering ', t_nd, ' s)'
    call report(nnz(3) > 0.0_wp .and. nnz(3) <= 1.5_wp*nnz(1), name//': nnz(L) nd <= 1.5 x METIS', &
                nnz(3)/max(nnz(1), 1.0_wp), 1.5_wp)
  end subroutine check_general

  !> A general mesh whose system lacks its pattern, or whose coordinates do not match,
  !! is reported, not crashed on.
  subroutine check_general_bad()
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    integer, allocatable :: last(:), perm(:)
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg

    call general_body(rectangle_body(6, 4, ELEM_Q1, [BC_CLAMPED, BC_FREE, BC_CONTACT, BC_FREE]), 0.2_wp, 1, &
                      msh, sys, last)
    call coordinate_bisection(msh%xy, sys%free_of, [integer ::], [integer ::], [integer ::], last, perm, err)
    call error_parts(err, info, msg)
    call report(info /= 0 .and. size(perm) == 0 .and. len_trim(msg) > 0, &
                'general mesh, system without a pattern rejected: '//trim(msg))
    call coordinate_bisection(msh%xy(:, 2:), sys%free_of, sys%dof_of, sys%colptr, sys%rowind, last, perm, err)
    call error_parts(err, info, msg)
    call report(info /= 0 .and. len_trim(msg) > 0, 'general mesh of another size rejected: '//trim(msg))
    sys%rowind(1) = sys%n + 5
    call order_body(msh, sys, last, perm, info, msg)
    call report(info /= 0 .and. len_trim(msg) > 0, 'general mesh, row index out of range rejected: '//trim(msg))
  end subroutine check_general_bad

  !> Ordering a 1024 x 512 cell grid (about 1M DOFs; only free_of is needed): time printed.
  subroutine check_large()
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    integer, allocatable :: last(:), perm(:)
    logical, allocatable :: seen(:)
    integer :: k, info, n
    type(error_t) :: err
    real(wp) :: t0, t
    character(len=256) :: msg

    msh%nx = 1024
    msh%ny = 512
    msh%nnode = (msh%nx + 1)*(msh%ny + 1)
    sys%ndof = 2*msh%nnode
    ! left side clamped: the nodes with i = 0 have no free DOFs
    call number_free_dofs([(mod((k - 1)/2, msh%nx + 1) == 0, k=1, sys%ndof)], sys)
    n = sys%n
    last = [(sys%free_of(2*(node_id(msh, k, 0) - 1) + 2), k=1, msh%nx)]
    t0 = wtime()
    call grid_dissection(msh%nx, msh%ny, sys%free_of, sys%n, last, perm, err)
    call error_parts(err, info, msg)
    t = wtime() - t0
    write (output_unit, '(a,i0,a,f0.3,a)') '      nested dissection of 1024x512 cells (n = ', n, '): ', t, ' s'
    allocate (seen(n))
    seen = .false.
    seen(last) = .true.
    do k = 1, size(perm)
      if (seen(perm(k))) exit
      seen(perm(k)) = .true.
    end do
    call report(info == 0 .and. size(perm) == n - size(last) .and. all(seen), &
                '1024x512 cells: a permutation of the free non-interface DOFs')
  end subroutine check_large

  !> Whether each node's DOFs in perm are consecutive, in increasing component order (the
  !! assembly's DOF map: node k, component c is free DOF free_of(node_dof(k, c))).
  logical function node_dofs_consecutive(sys, nnode, perm, is_last) result(ok)
    type(body_system_t), intent(in) :: sys    !< the body's numbering
    integer, intent(in) :: nnode              !< its nodes
    integer, intent(in) :: perm(:)            !< an interior order (covers_rest)
    logical, intent(in) :: is_last(:)         !< the DOFs ordered last by the caller
    integer, allocatable :: pos(:)
    integer :: k, c, f, prev
    allocate (pos(sys%n))
    pos = 0
    pos(perm) = [(k, k=1, size(perm))]
    ok = .true.
    do k = 1, nnode
      prev = 0
      do c = 1, 3
        f = sys%free_of(node_dof(k, c))
        if (f == 0) cycle
        if (is_last(f)) cycle
        if (prev > 0) ok = ok .and. pos(f) == prev + 1
        prev = pos(f)
      end do
    end do
  end function node_dofs_consecutive

  !> A solid box's node order: a permutation of the DOFs not last, nodes together and
  !! consecutive, the nodes of the pattern the mesh's; factored with ORD_NODES and the contact
  !! DOFs last in a scrambled order: the trailing block, the solution and the flexibility of
  !! METIS on the DOF graph.
  subroutine check_nodes_3d(name, nx, ny, nz, elem, bcs)
    character(len=*), intent(in) :: name
    integer, intent(in) :: nx, ny, nz, elem, bcs(6)
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(chol_t) :: ch
    integer, allocatable :: last(:), perm(:), group_of(:), members(:), gptr(:), node_of_group(:)
    logical, allocatable :: is_last(:), has_inner(:)
    real(wp), allocatable :: sgn(:), flex(:, :, :)
    real(wp) :: d
    integer :: info, m, o, ng, g, k, p
    logical :: ok
    type(error_t) :: err
    character(len=256) :: msg
    character(len=96) :: tag

    call box_system(nx, ny, nz, elem, bcs, msh, sys, last)
    m = size(last)
    last = [(last(k), k=m, 1, -2), (last(k), k=m - 1, 1, -2)]   ! a scrambled given order
    allocate (is_last(sys%n))
    is_last = .false.
    is_last(last) = .true.
    call node_dissection(sys%colptr, sys%rowind, last, perm, err)
    call error_parts(err, info, msg)
    call report(info == 0, name//': node ordering info = 0 '//trim(msg))
    if (info /= 0) return
    ok = size(perm) == sys%n - m
    if (ok) ok = covers_rest(perm, is_last)
    call report(ok, name//': a permutation of exactly the free DOFs not last')
    if (.not. ok) return
    call report(node_dofs_consecutive(sys, msh%nnode, perm, is_last), &
                name//': each node''s DOFs together, consecutive, in component order')
    call report(.not. node_dofs_consecutive(sys, msh%nnode, perm(size(perm):1:-1), is_last), &
                name//': (the same check fails on the reversed order)')

    ! the nodes of the pattern are the mesh's nodes with a DOF not last
    call node_groups(sys%colptr, sys%rowind, is_last, group_of, members, gptr, ng, err)
    allocate (has_inner(msh%nnode), node_of_group(max(ng, 1)))
    has_inner = .false.
    do k = 1, sys%n
      if (.not. is_last(k)) has_inner(dof_node(sys%dof_of(k))) = .true.
    end do
    ok = .not. err%failed() .and. ng == count(has_inner)
    do g = 1, max(ng, 0)
      node_of_group(g) = dof_node(sys%dof_of(members(gptr(g))))
      do p = gptr(g), gptr(g + 1) - 1
        ok = ok .and. dof_node(sys%dof_of(members(p))) == node_of_group(g) .and. group_of(members(p)) == g
      end do
    end do
    if (ng > 1) ok = ok .and. all(node_of_group(2:ng) > node_of_group(1:ng - 1))
    call report(ok, name//': the pattern''s nodes are the mesh''s (one per node with a DOF not last)', &
                real(ng, wp), real(count(has_inner), wp))

    allocate (sgn(m), flex(m, m, 2))
    sgn = -1.0_wp
    do o = 1, 2
      tag = name//merge(' nodes', ' metis', o == 1)
      call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, merge(ORD_NODES, ORD_METIS, o == 1), &
                     err, last=last)
      call error_parts(err, info, msg)
      call report(info == 0 .and. ch%interface_last_ok, trim(tag)//': factor ok, contact DOFs last in the given order '//trim(msg))
      if (info /= 0) cycle
      call solve_and_flex(ch, sys, last, sgn, tag, flex(:, :, o))
    end do
    d = norm2(flex(:, :, 1) - flex(:, :, 2))/norm2(flex(:, :, 2))
    call report_le(d, FLEX_TOL, name//' nodes: flexibility = METIS''s (relative)')
  end subroutine check_nodes_3d

  !> The fill of the node order on a k^3 box of hexahedra (bottom clamped, the top's normal
  !! DOFs last): nnz(L) within 1.2x METIS's on the DOF graph and below the natural order's;
  !! the program's choice for 'nd' in 3D (new_factor) is the node order, factoring the same.
  subroutine check_fill_3d(k)
    integer, intent(in) :: k
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(chol_t) :: ch
    type(factor_cfg_t) :: fc
    class(factor_t), allocatable :: fac
    integer, allocatable :: last(:)
    real(wp) :: nnz(3), t(3)
    integer :: o, info
    integer, parameter :: ords(3) = [ORD_NODES, ORD_METIS, ORD_NATURAL]
    character(len=*), parameter :: onames(3) = [character(len=7) :: 'nodes', 'metis', 'natural']
    character(len=256) :: msg
    character(len=32) :: name
    type(error_t) :: err
    logical :: ok

    write (name, '(a,i0,a)') 'box Q1 ', k, '^3'
    call box_system(k, k, k, ELEM_Q1, [BC_FREE, BC_FREE, BC_CLAMPED, BC_CONTACT, BC_FREE, BC_FREE], msh, sys, last)
    nnz = 0.0_wp
    do o = 1, 3
      call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ords(o), err, last=last)
      call error_parts(err, info, msg)
      call report(info == 0 .and. ch%interface_last_ok, trim(name)//' '//trim(onames(o))//': factor ok, last last '//trim(msg))
      nnz(o) = real(ch%nnz_factor, wp)
      t(o) = ch%t_analyze
      call ch%free()
    end do
    write (output_unit, '(a,3(a,es10.3),a,2(f0.3,a))') '      '//trim(name)//' nnz(L):', ' nodes=', nnz(1), &
      ' metis=', nnz(2), ' natural=', nnz(3), ' (analyze nodes ', t(1), ' s, metis ', t(2), ' s)'
    call report(nnz(1) > 0.0_wp .and. nnz(1) <= 1.2_wp*nnz(2), trim(name)//': nnz(L) nodes <= 1.2 x METIS on the DOFs', &
                nnz(1)/max(nnz(2), 1.0_wp), 1.2_wp)
    call report(nnz(1) > 0.0_wp .and. nnz(1) < nnz(3), trim(name)//': nnz(L) nodes < natural order''s', &
                nnz(1)/max(nnz(3), 1.0_wp), 1.0_wp)

    ! ordering 'nd' in 3D: the node order, the interface last (the plane: the caller's order)
    fc%ordering = ORDER_ND
    call new_factor(fc, 1, fac)
    ok = .false.
    select type (fac)
    type is (cholmod_factor_t)
      ok = fac%ordering == ORD_NODES .and. .not. fac%wants_interior_order()
    end select
    call report(ok, 'ordering ''nd'' of a solid body: CHOLMOD with the node order, no order wanted from the caller')
    call fac%factorize(sys%n, last, err, sys%colptr, sys%rowind, sys%val)
    call error_parts(err, info, msg)
    call report(info == 0 .and. index(fac%summary(), 'cholmod/nodes') > 0 .and. real(fac%stats%nnz_factor, wp) == nnz(1), &
                trim(name)//' ''nd'': factorize as ORD_NODES: '//fac%summary())
    call fac%free()
    call set_dimension(2)
    call new_factor(fc, 1, fac)
    ok = .false.
    select type (fac)
    type is (cholmod_factor_t)
      ok = fac%ordering == ORD_GIVEN .and. fac%wants_interior_order()
    end select
    call report(ok, 'ordering ''nd'' of a plane body: the caller''s order (unchanged)')
    call set_dimension(3)
  end subroutine check_fill_3d

  !> Bad inputs of the node order and of ORD_AUTO are reported, not crashed on; ORD_AUTO
  !! without DOFs last is CHOLMOD's own choice (AMD or METIS).
  subroutine check_nodes_bad()
    type(mesh_t) :: msh
    type(body_system_t) :: sys
    type(chol_t) :: ch
    integer, allocatable :: last(:), perm(:), rows(:)
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg

    call box_system(3, 3, 3, ELEM_Q1, [BC_FREE, BC_FREE, BC_CLAMPED, BC_CONTACT, BC_FREE, BC_FREE], msh, sys, last)
    call node_dissection(sys%colptr, sys%rowind, [last, sys%n + 1], perm, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. size(perm) == 0 .and. len_trim(msg) > 0, &
                'node ordering: an interface DOF out of range rejected: '//trim(msg))
    call node_dissection(sys%colptr, sys%rowind, [last, last(1)], perm, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'node ordering: a repeated interface DOF rejected: '//trim(msg))
    rows = sys%rowind
    rows(5) = sys%n
    call node_dissection(sys%colptr, rows, last, perm, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. size(perm) == 0 .and. len_trim(msg) > 0, &
                'node ordering: a row index out of range rejected: '//trim(msg))
    call node_dissection(sys%colptr, sys%rowind, [(info, info=1, sys%n)], perm, err)
    call error_parts(err, info, msg)
    call report(info == 0 .and. size(perm) == 0, 'node ordering: every DOF last, an empty order '//trim(msg))
    call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_AUTO, err, last=last)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'ORD_AUTO with DOFs last rejected: '//trim(msg))
    call ch%factor(sys%n, sys%colptr, sys%rowind, sys%val, FACT_CHOLMOD, ORD_AUTO, err)
    call error_parts(err, info, msg)
    call report(info == 0 .and. (ch%ordering_used == 2 .or. ch%ordering_used == 3), &
                'ORD_AUTO without DOFs last: CHOLMOD''s own choice (2 AMD, 3 METIS) '//trim(msg), &
                real(ch%ordering_used, wp))
    call ch%free()
  end subroutine check_nodes_bad

  !> The body's CHOLMOD factor has the interface DOFs last in its permutation.
  logical function interface_last(cbody)
    type(body_condensed_t), intent(in) :: cbody
    interface_last = .false.
    select type (f => cbody%fac)
    type is (cholmod_factor_t)
      interface_last = f%chol%interface_last_ok
    end select
  end function interface_last

end program test_ordering
