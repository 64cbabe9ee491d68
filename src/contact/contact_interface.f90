!> The contact interface of all contact pairs: one constraint row per slave node of each
!! pair, rows of pair p stacked after those of pairs 1..p-1 (M rows in all), each row with
!! its two sides: side 1 the pair's body with the lower id, side 2 the other. The gap of a
!! row is B_s1 u_s1 + B_s2 u_s2 - g0 <= 0, each side's coefficients on its own body's DOFs.
!! A body's contact rows are its sides of every pair it takes part in (`body_slots`), so a
!! body in several pairs is condensed on all of them at once. The rows come from two edge
!! groups per pair (named groups, or the rectangle sides declared 'contact') paired by dual
!! mortar (module mortar; row j = the weighted normal gap at slave node j). Each contact node
!! carries a frame (`frame_of`: its unit normal, then NDIM - 1 unit tangents), and each row is
!! one direction of its node's frame (`dir`: DIR_NORMAL, or the tangent 1 .. NDIM - 1). A
!! frictional pair has, after its normal rows, NDIM - 1 tangential rows per slave node (the
!! same mortar weights along each tangent: the weighted slip), whose force is bounded by a
!! box (Tresca) or by mu times the node's normal force (Coulomb): `row_bounds`.
module contact_interface
  use kinds, only: wp, i8
  use space, only: NDIM, NCOMP, node_dof, dof_comp, frame_of
  use config, only: body_cfg_t, contact_cfg_t, BC_CONTACT, side_names, pair_oriented, FRICTION_NONE, FRICTION_TRESCA, &
                    OVERLAP_INTERFERENCE, &
                    FRICTION_COULOMB
  use mesh, only: mesh_t, group_index, group_names, nodes_only, nodes_only_refusal
  use mortar, only: mortar_t, mortar_build
  use strings, only: i2s, sci
  use int_hash, only: int_hash_t, hash_init, hash_slot, HASH_EMPTY
  use assembly, only: body_system_t
  use errors, only: error_t, ERR_INPUT, ERR_MEMORY
  implicit none (type, external)
  private

  !> The rows of one side (compressed rows over the side body's DOFs 2*(node-1)+c).
  type, public :: brows_t
    integer, allocatable :: ptr(:)          !< (m+1) row k is entries ptr(k) .. ptr(k+1)-1
    integer, allocatable :: dof(:)          !< DOF of the side's body of each entry
    real(wp), allocatable :: val(:)         !< coefficient of each entry [-]
  end type brows_t

  !> The contact interface: m constraint rows over all pairs, one per contact node of each
  !! pair's slave side.
  type, public :: interface_t
    integer :: m = 0                        !< contact constraints of all pairs
    integer :: npair = 0                    !< contact pairs
    logical :: mortar = .false.             !< rows from dual mortar on named groups
    integer, allocatable :: pair_ptr(:)     !< (npair+1) rows of pair p: pair_ptr(p) .. pair_ptr(p+1)-1
    integer, allocatable :: pair_body(:, :) !< (2,npair) the body on side 1 and on side 2
    integer, allocatable :: pair_slave(:)   !< (npair) the side whose nodes carry the rows (1 or 2)
    integer, allocatable :: pair_of(:)      !< (m) the pair of each row
    real(wp), allocatable :: s(:)           !< (m) arc length along the pair's slave contact chain [length]
    real(wp), allocatable :: xy(:, :)       !< (NDIM,m) slave node coordinates [length]
    !> (NDIM,NDIM,m) the frame of the row's slave node: column 1 the unit normal outward from
    !! the slave body, columns 2.. the unit tangents (frame_of)
    real(wp), allocatable :: frame(:, :, :)
    integer, allocatable :: dir(:)          !< (m) the row's direction in its node's frame: DIR_NORMAL, or tangent 1..NDIM-1
    integer, allocatable :: nrow(:)         !< (m) the normal row of the row's slave node (itself for a normal row)
    integer, allocatable :: pair_friction(:)   !< (npair) FRICTION_* of the pair (NONE when it has no tangential rows)
    real(wp), allocatable :: pair_mu(:)        !< (npair) Coulomb coefficient [-]
    real(wp), allocatable :: pair_slip(:)      !< (npair) Tresca's bound of the shear traction [stress]
    real(wp), allocatable :: g0(:)          !< (m) initial normal gap [length]
    real(wp), allocatable :: trib(:)        !< (m) tributary length D_jj [length]
    integer, allocatable :: node(:, :)      !< (m,2) mesh node of each side's body (0: none, mortar master)
    type(brows_t) :: b(2)                   !< the rows of side 1 and side 2
  end type interface_t

  integer, parameter, public :: DIR_NORMAL = 0    !< a row of the normal gap (force >= 0); dir > 0: a row of the slip

  public :: build_interface, contact_resultant, body_slots, pair_rows, slot_row, slot_side, row_bounds, has_friction
  public :: row_direction, row_directions, disc_rows, disc_positions

contains

  !> The direction of row k: its node's normal for a normal row, the row's tangent for a
  !! tangential one [-].
  pure function row_direction(itf, k) result(d)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: k                  !< a row, 1..m
    real(wp) :: d(NDIM)
    d = itf%frame(:, itf%dir(k) + 1, k)
  end function row_direction

  !> The directions of rows i..j, one column per row [-].
  pure function row_directions(itf, i, j) result(d)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: i, j               !< the first and the last row
    real(wp) :: d(NDIM, max(0, j - i + 1))
    integer :: k
    do k = i, j
      d(:, k - i + 1) = itf%frame(:, itf%dir(k) + 1, k)
    end do
  end function row_directions


  !> The positions of body a's contact rows in the (m, 2) side layout of the contact
  !! vectors (row + (side - 1) m), pair by pair in the order of the pairs: body a's own
  !! contact vector is x(slots) of a side-layout array x.
  function body_slots(itf, a) result(slots)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a                  !< body
    integer, allocatable :: slots(:)
    integer :: p, s, n, i
    n = 0
    do p = 1, itf%npair
      do s = 1, 2
        if (itf%pair_body(s, p) == a) n = n + itf%pair_ptr(p + 1) - itf%pair_ptr(p)
      end do
    end do
    allocate (slots(n))
    n = 0
    do p = 1, itf%npair
      do s = 1, 2
        if (itf%pair_body(s, p) /= a) cycle
        do i = itf%pair_ptr(p), itf%pair_ptr(p + 1) - 1
          n = n + 1
          slots(n) = i + (s - 1)*itf%m
        end do
      end do
    end do
  end function body_slots

  !> The contact row of a slot (its position row + (side - 1) m in the side layout).
  elemental integer function slot_row(slot, m)
    integer, intent(in) :: slot             !< a position in the side layout
    integer, intent(in) :: m                !< contact rows of all pairs
    slot_row = slot - ((slot - 1)/m)*m
  end function slot_row

  !> The side (1 or 2) of a slot.
  elemental integer function slot_side(slot, m)
    integer, intent(in) :: slot             !< a position in the side layout
    integer, intent(in) :: m                !< contact rows of all pairs
    slot_side = (slot - 1)/m + 1
  end function slot_side

  !> The rows of pair p, as a range.
  pure function pair_rows(itf, p) result(r)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: p                  !< pair
    integer :: r(2)                           !< first and last row
    r = [itf%pair_ptr(p), itf%pair_ptr(p + 1) - 1]
  end function pair_rows

  !> Whether any pair has tangential rows.
  pure logical function has_friction(itf)
    type(interface_t), intent(in) :: itf
    has_friction = any(itf%dir > DIR_NORMAL)
  end function has_friction

  !> The pairs of tangential rows that carry one node's tangential force in space (its tangent
  !! 1 and tangent 2 rows), whose force is bounded by a disc |(l_t1, l_t2)| <= t (METHOD-3D
  !! section 3); none in the plane, where a node's one tangential row has an interval, as has
  !! a node on a plane of symmetry in space (symmetry_tangents).
  pure function disc_rows(itf) result(pr)
    type(interface_t), intent(in) :: itf
    integer, allocatable :: pr(:, :)          !< (2, nodes) the tangent-1 row, the tangent-2 row
    integer, allocatable :: t(:, :)
    integer :: k, n
    if (NDIM /= 3 .or. itf%m == 0) then
      allocate (pr(2, 0))
      return
    end if
    ! each node's tangent-1 and tangent-2 rows (0: none; a node on a plane of symmetry has one)
    allocate (t(2, itf%m))
    t = 0
    do k = 1, itf%m
      if (itf%dir(k) > DIR_NORMAL) t(itf%dir(k), itf%nrow(k)) = k
    end do
    n = count(t(1, :) > 0 .and. t(2, :) > 0)
    allocate (pr(2, n))
    n = 0
    do k = 1, itf%m
      if (t(1, k) == 0 .or. t(2, k) == 0) cycle
      n = n + 1
      pr(:, n) = t(:, k)
    end do
  end function disc_rows

  !> The discs among the rows `rows` (a body's rows, or any subset holding both rows of each
  !! disc it touches), as positions in `rows`.
  pure function disc_positions(itf, rows) result(pp)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: rows(:)            !< contact rows, 1..m
    integer, allocatable :: pp(:, :)          !< (2, discs) positions in rows
    integer, allocatable :: pr(:, :), pos(:)
    integer :: i, n
    pr = disc_rows(itf)
    allocate (pos(itf%m))
    pos = 0
    do i = 1, size(rows)
      pos(rows(i)) = i
    end do
    n = count(pos(pr(1, :)) > 0 .and. pos(pr(2, :)) > 0)
    allocate (pp(2, n))
    n = 0
    do i = 1, size(pr, 2)
      if (pos(pr(1, i)) == 0 .or. pos(pr(2, i)) == 0) cycle
      n = n + 1
      pp(:, n) = pos(pr(:, i))
    end do
  end function disc_positions

  !> The bounds of the contact forces on the rows: a normal row's force is >= 0 (no upper
  !! bound, +huge); a tangential row's lies in [-t, t] with t = slip_bound x tributary length
  !! (Tresca) or mu x the node's normal force lam_n (Coulomb; lam_n < 0 counts as 0). In
  !! space t is the radius of the node's disc (disc_rows), given on both its rows.
  !! With `start` (no normal force known yet) a Coulomb row is unbounded: the first solve
  !! sticks everywhere, and its normal forces give the first bounds.
  pure subroutine row_bounds(itf, lam_n, lb, ub, start)
    type(interface_t), intent(in) :: itf
    real(wp), intent(in) :: lam_n(:)          !< (m) normal forces of the rows (read at the normal rows) [force]
    real(wp), intent(out) :: lb(:), ub(:)     !< (m) [force]
    logical, intent(in), optional :: start
    integer :: k, p
    real(wp) :: t
    logical :: first
    first = .false.
    if (present(start)) first = start
    do k = 1, itf%m
      if (itf%dir(k) == DIR_NORMAL) then
        lb(k) = 0.0_wp
        ub(k) = huge(1.0_wp)
      else
        p = itf%pair_of(k)
        if (itf%pair_friction(p) == FRICTION_TRESCA) then
          t = itf%pair_slip(p)*itf%trib(k)
        else if (first) then
          t = huge(1.0_wp)
        else
          t = itf%pair_mu(p)*max(lam_n(itf%nrow(k)), 0.0_wp)
        end if
        lb(k) = -t
        ub(k) = t
      end if
    end do
  end subroutine row_bounds

  !> The resultant of the contact forces of `side` on its body over the rows `first..last`,
  !! -sum of B' lam by component [force]: what balances the body's applied load when contact
  !! alone holds it (the sum of the nodal normal forces is not a resultant on a curved line).
  pure function contact_resultant(itf, side, lam, first, last) result(f)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: side               !< side (1 or 2)
    real(wp), intent(in) :: lam(:)            !< (m) contact forces [force]
    integer, intent(in) :: first, last        !< rows
    real(wp) :: f(NCOMP)
    integer :: k, e, c
    f = 0.0_wp
    do k = first, last
      do e = itf%b(side)%ptr(k), itf%b(side)%ptr(k + 1) - 1
        c = dof_comp(itf%b(side)%dof(e))
        f(c) = f(c) - itf%b(side)%val(e)*lam(k)
      end do
    end do
  end function contact_resultant

  !> The contact interface of every pair of the deck, each by dual mortar on two edge
  !! groups: the named groups of &contact, or a rectangle's side declared 'contact' (its
  !! mesh has the sides as groups 'left', 'right', 'bottom', 'top'). On matching lines the
  !! mortar rows are the node-to-node ones to rounding, so one path serves every scene.
  subroutine build_interface(body, pairs, named, msh, sys, itf, err)
    type(body_cfg_t), intent(in) :: body(:)          !< the bodies (their contact sides)
    type(contact_cfg_t), intent(in) :: pairs(:)      !< the pairs (groups, slave, initial gap)
    logical, intent(in) :: named                     !< the deck names its pairs (&contact bodies=A,B)
    type(mesh_t), intent(in) :: msh(:)               !< meshes of the bodies
    type(body_system_t), intent(in) :: sys(:)        !< assembled systems
    type(interface_t), intent(out) :: itf            !< the contact rows of all pairs
    type(error_t), intent(out) :: err                !< the bad input (ERR_INPUT), if any
    type(interface_t), allocatable :: one(:)
    type(contact_cfg_t) :: cc
    type(contact_cfg_t), allocatable :: ccs(:)
    logical, allocatable :: taken(:)
    integer :: p, a, s, side, np, q, k

    np = size(pairs)
    allocate (one(np))
    itf%npair = np
    itf%mortar = .true.
    allocate (itf%pair_ptr(np + 1), itf%pair_body(2, np), itf%pair_slave(np), itf%pair_friction(np), itf%pair_mu(np), &
              itf%pair_slip(np))
    itf%pair_ptr(1) = 1
    allocate (ccs(np))
    do p = 1, np
      ccs(p) = pair_oriented(pairs(p))
      if (len_trim(ccs(p)%body_group(1)) == 0) then
        do s = 1, 2
          a = ccs(p)%bodies(s)
          side = findloc(body(a)%bc, BC_CONTACT, dim=1)
          if (side == 0) then
            call err%set(ERR_INPUT, 'body '//i2s(a)//' has no contact side')
            return
          end if
          ccs(p)%body_group(s) = side_names(side)
        end do
      end if
    end do
    call check_shared_edges(ccs, named, msh, err)
    if (err%failed()) return
    do p = 1, np
      cc = ccs(p)
      ! a later pair of the same two bodies (a block in a corner): the same slave as the
      ! first, and its slave nodes that carry rows there carry none here (a crosspoint:
      ! at the corner node the normal row of one pair and the tangential row of the other
      ! act on the same displacement, and matching meshes make them the same row)
      allocate (taken(msh(cc%bodies(1))%nnode + msh(cc%bodies(2))%nnode))
      taken = .false.
      do q = 1, p - 1
        if (any(itf%pair_body(:, q) /= cc%bodies)) cycle
        if (cc%slave == 0) cc%slave = cc%bodies(itf%pair_slave(q))
        if (cc%bodies(itf%pair_slave(q)) /= cc%slave) cycle
        s = itf%pair_slave(q)
        do k = 1, one(q)%m
          if (one(q)%node(k, s) > 0) taken(one(q)%node(k, s)) = .true.
        end do
      end do
      call mortar_pair(cc, named, msh, sys, one(p), err, taken)
      deallocate (taken)
      if (err%failed()) return
      itf%pair_body(:, p) = cc%bodies
      itf%pair_slave(p) = one(p)%pair_slave(1)
      itf%pair_friction(p) = one(p)%pair_friction(1)
      itf%pair_mu(p) = cc%mu
      itf%pair_slip(p) = cc%slip_bound
      itf%pair_ptr(p + 1) = itf%pair_ptr(p) + one(p)%m
    end do
    call stack_pairs(one, itf)
  end subroutine build_interface

  !> Two pairs of the same two bodies share no edge: two differently named groups over the
  !! same edges (a Gmsh curve with two physical names) in two pairs of the same bodies would
  !! give the edges two sets of contact rows and split their force arbitrarily. A surface in
  !! pairs with different bodies (a lid's bottom on two blocks) is allowed: each pair's rows
  !! hold where its partner's surface covers it. Per body, the edges of its groups in pairs
  !! go into one hash set keyed by the edge's two nodes (either order) and the partner body,
  !! each with the pair end that put it there (linear in the edges). Unknown or node-only
  !! groups are left to mortar_pair's messages.
  subroutine check_shared_edges(pairs, named, msh, err)
    type(contact_cfg_t), intent(in) :: pairs(:)   !< the pairs, oriented, rectangle sides resolved
    logical, intent(in) :: named                  !< the deck names its pairs (messages)
    type(mesh_t), intent(in) :: msh(:)            !< meshes of all bodies
    type(error_t), intent(out) :: err             !< ERR_INPUT naming both groups and a shared edge (ERR_MEMORY: no room to compare)
    type(int_hash_t) :: h
    integer, allocatable :: owner(:), nend(:)
    integer :: a, p, s, g, e, slot, n1, n2, n3, ne, q, t
    type(error_t) :: mem
    integer(i8) :: key
    logical :: keyed

    allocate (nend(size(msh)))
    ! the partner in the key unless nnode**2 * nbody could overflow it (then any shared edge
    ! is refused, as for the same partner)
    nend = 0
    do p = 1, size(pairs)
      do s = 1, 2
        nend(pairs(p)%bodies(s)) = nend(pairs(p)%bodies(s)) + 1
      end do
    end do
    do a = 1, size(msh)
      if (nend(a) < 2) cycle
      associate (m => msh(a))
        keyed = real(m%nnode, wp)**(NDIM)*real(size(msh), wp) < 4.0e18_wp
        if (NDIM == 3 .and. real(m%nnode, wp)**3 >= 4.0e18_wp) cycle     ! a face's key would not fit 64 bits
        ne = 0
        do p = 1, size(pairs)
          do s = 1, 2
            if (pairs(p)%bodies(s) /= a) cycle
            g = group_index(m, pairs(p)%body_group(s))
            if (g > 0) ne = ne + m%group(g)%nedge
          end do
        end do
        call hash_init(h, ne, mem)
        if (mem%failed()) then
          call err%set(ERR_MEMORY, 'body '//i2s(a)//': not enough memory to compare its contact groups'' '// &
                       i2s(ne)//' edges')
          return
        end if
        allocate (owner(0:h%mask))
        do p = 1, size(pairs)
          do s = 1, 2
            if (pairs(p)%bodies(s) /= a) cycle
            g = group_index(m, pairs(p)%body_group(s))
            if (g == 0) cycle
            do e = 1, m%group(g)%nedge
              n1 = minval(m%group(g)%edge(:, e), mask=m%group(g)%edge(:, e) > 0)
              n2 = maxval(m%group(g)%edge(:, e))
              key = int(n1 - 1, i8)*int(m%nnode, i8) + int(n2 - 1, i8)
              if (NDIM == 3) then    ! a face: its smallest, second smallest and largest node
                n3 = minval(m%group(g)%edge(:, e), mask=m%group(g)%edge(:, e) > n1)
                key = (int(n1 - 1, i8)*int(m%nnode, i8) + int(n3 - 1, i8))*int(m%nnode, i8) + int(n2 - 1, i8)
              end if
              if (keyed) key = key*int(size(msh), i8) + int(pairs(p)%bodies(3 - s) - 1, i8)
              slot = hash_slot(h, key)
              if (h%key(slot) == HASH_EMPTY) then
                h%key(slot) = key
                owner(slot) = 2*p + s - 2
                cycle
              end if
              q = (owner(slot) + 1)/2
              t = owner(slot) - 2*q + 2
              if (owner(slot) == 2*p + s - 2) cycle   ! an edge listed twice in one group: the mesh reader's business
              call err%set(ERR_INPUT, 'body '//i2s(a)//': contact group '''//trim(pairs(q)%body_group(t))// &
                ''' ('//pair_words(q)//') and contact group '''//trim(pairs(p)%body_group(s))// &
                ''' ('//pair_words(p)//') share edges, e.g. the edge of nodes '// &
                i2s(m%node_tag(n1))//' and '//i2s(m%node_tag(n2))//' from ('//sci(m%xy(1, n1))//', '// &
                sci(m%xy(2, n1))//') to ('//sci(m%xy(1, n2))//', '//sci(m%xy(2, n2))//'); an edge of a body '// &
                'is in one pair with each other body at most (two names of one Gmsh curve are one surface)')
              return
            end do
          end do
        end do
        deallocate (owner)
      end associate
    end do
  contains
    function pair_words(k) result(w)
      integer, intent(in) :: k
      character(len=:), allocatable :: w
      if (named) then
        w = 'pair '//i2s(k)//', &contact bodies='//i2s(pairs(k)%bodies(1))//','//i2s(pairs(k)%bodies(2))
      else
        w = 'pair '//i2s(k)
      end if
    end function pair_words
  end subroutine check_shared_edges

  !> Stack the pairs' rows (each built with its own rows 1..m_p) into itf, whose pair
  !! fields are set.
  subroutine stack_pairs(one, itf)
    type(interface_t), intent(in) :: one(:)
    type(interface_t), intent(inout) :: itf
    integer :: p, s, m, r0, ne(2), k, e0
    m = itf%pair_ptr(size(one) + 1) - 1
    itf%m = m
    allocate (itf%s(m), itf%xy(NDIM, m), itf%g0(m), itf%trib(m), itf%node(m, 2), itf%frame(NDIM, NDIM, m), &
              itf%pair_of(m), itf%dir(m), itf%nrow(m))
    ne = 0
    do p = 1, size(one)
      do s = 1, 2
        ne(s) = ne(s) + one(p)%b(s)%ptr(one(p)%m + 1) - 1
      end do
    end do
    do s = 1, 2
      allocate (itf%b(s)%ptr(m + 1), itf%b(s)%dof(ne(s)), itf%b(s)%val(ne(s)))
      itf%b(s)%ptr(1) = 1
    end do
    do p = 1, size(one)
      r0 = itf%pair_ptr(p) - 1
      associate (o => one(p), rows => [(r0 + k, k=1, one(p)%m)])
        itf%s(rows) = o%s
        itf%xy(:, rows) = o%xy
        itf%frame(:, :, rows) = o%frame
        itf%g0(rows) = o%g0
        itf%trib(rows) = o%trib
        itf%node(rows, :) = o%node
        itf%dir(rows) = o%dir
        itf%nrow(rows) = o%nrow + r0
        itf%pair_of(rows) = p
        do s = 1, 2
          e0 = itf%b(s)%ptr(r0 + 1) - 1
          itf%b(s)%ptr(r0 + 2:r0 + o%m + 1) = o%b(s)%ptr(2:o%m + 1) + e0
          ne(s) = o%b(s)%ptr(o%m + 1) - 1
          itf%b(s)%dof(e0 + 1:e0 + ne(s)) = o%b(s)%dof(1:ne(s))
          itf%b(s)%val(e0 + 1:e0 + ne(s)) = o%b(s)%val(1:ne(s))
        end do
      end associate
    end do
  end subroutine stack_pairs

  !> The rows of one pair of two named edge groups by dual mortar (module mortar), side 1
  !! cc%bodies(1), side 2 cc%bodies(2): the slave is cc%slave, or the side whose contact
  !! group has the shorter mean edge (side 1 on a tie). A slave node carries no row when its
  !! normal displacement and that of every master node its row involves are prescribed (the
  !! constraint would only repeat the supports): found by a first build, then the rows are
  !! built again without those nodes, and without the nodes `taken` by an earlier pair.
  !! err = ERR_INPUT for an unknown group, a group facing nothing, or an initial overlap.
  subroutine mortar_pair(cc, named, msh, sys, itf, err, taken)
    type(contact_cfg_t), intent(in) :: cc            !< the pair, cc%bodies(1) < cc%bodies(2)
    logical, intent(in) :: named                     !< the deck names its pairs (messages)
    type(mesh_t), intent(in) :: msh(:)               !< meshes of all bodies
    type(body_system_t), intent(in) :: sys(:)        !< systems of all bodies
    type(interface_t), intent(out) :: itf            !< the pair's rows 1..m_p
    type(error_t), intent(out) :: err
    !> slave nodes that carry rows in an earlier pair of the same bodies: none here
    logical, intent(in), optional :: taken(:)
    integer :: g(2), s, sl, ma, j, e, k, ne, nr, r
    real(wp) :: hmean(2), tol, gmin, ext
    logical, allocatable :: removable(:), keep_t(:, :)
    real(wp), allocatable :: gdist(:), nrm(:, :)
    character(len=300) :: what(2)               ! each side's words for messages
    type(mortar_t) :: mt
    type(error_t) :: why
    character(len=:), allocatable :: gtext      ! a sentence about a group (built by a subroutine: threads)

    do s = 1, 2
      if (named) then
        what(s) = '&contact bodies='//i2s(cc%bodies(1))//','//i2s(cc%bodies(2))//': body '//i2s(cc%bodies(s))
      else
        what(s) = '&contact body'//i2s(s)//'_group='''//trim(cc%body_group(s))//''': body '//i2s(cc%bodies(s))
      end if
    end do
    do s = 1, 2
      associate (m => msh(cc%bodies(s)))
        g(s) = group_index(m, cc%body_group(s))
        if (g(s) == 0) then
          if (named) then
            call group_names(m, gtext)
            call err%set(ERR_INPUT, trim(what(s))//' has no group '''//trim(cc%body_group(s))//''' with edges on '// &
                         'its boundary; its groups are '//gtext)
          else
            call group_names(m, gtext)
            call err%set(ERR_INPUT, trim(what(s))//' has no such group with edges on its boundary; its groups are '// &
                         gtext)
          end if
          return
        end if
        if (nodes_only(m, g(s))) then
          call nodes_only_refusal(m, g(s), 'contact needs', gtext)
          if (named) then
            call err%set(ERR_INPUT, trim(what(s))//': group '''//trim(cc%body_group(s))//''': '//gtext)
          else
            call err%set(ERR_INPUT, trim(what(s))//': '//gtext)
          end if
          return
        end if
        hmean(s) = 0.0_wp
        do e = 1, m%group(g(s))%nedge
          hmean(s) = hmean(s) + norm2(m%xy(:, m%group(g(s))%edge(2, e)) - m%xy(:, m%group(g(s))%edge(1, e)))
        end do
        hmean(s) = hmean(s)/max(1, m%group(g(s))%nedge)
      end associate
    end do
    sl = findloc(cc%bodies, cc%slave, dim=1)
    if (cc%slave == 0 .or. sl == 0) sl = merge(2, 1, hmean(2) < hmean(1)*(1.0_wp - 1.0e-12_wp))
    ma = 3 - sl
    itf%mortar = .true.
    itf%npair = 1
    itf%pair_slave = [sl]

    associate (ms => msh(cc%bodies(sl)), mm => msh(cc%bodies(ma)))
      allocate (removable(ms%nnode))
      removable = .false.
      if (present(taken)) removable = taken(1:ms%nnode)
      call mortar_build(ms%xy, ms%group(g(sl))%edge, removable, mm%xy, mm%group(g(ma))%edge, mt, why, &
                        ms%node_tag, mm%node_tag, ms%axisymmetric)
      if (.not. why%failed()) then
        do j = 1, mt%m
          removable(mt%snode(j)) = normal_fixed(sys(cc%bodies(sl)), mt%snode(j), mt%normal(:, j))
          do k = mt%mptr(j), mt%mptr(j + 1) - 1
            if (abs(mt%mval(k)) > 1.0e-12_wp) removable(mt%snode(j)) = removable(mt%snode(j)) .and. &
              normal_fixed(sys(cc%bodies(ma)), mt%mnod(k), mt%normal(:, j))
          end do
        end do
        if (any(removable)) call mortar_build(ms%xy, ms%group(g(sl))%edge, removable, mm%xy, mm%group(g(ma))%edge, &
                                              mt, why, ms%node_tag, mm%node_tag, ms%axisymmetric)
      end if
      if (why%failed()) then
        call err%set(ERR_INPUT, 'contact group '''//trim(cc%body_group(sl))//''' of body '//i2s(cc%bodies(sl))// &
                     ' (slave) and '''//trim(cc%body_group(ma))//''' of body '//i2s(cc%bodies(ma))//' (master): '// &
                     why%text())
        return
      end if

      ! an initial overlap beyond a thousandth of the slave's mean edge is bad input
      ! (the gap of a row divided by its slave weight sum: the distance, where the row's
      ! weights sum to more or less than one next to a removed node or at a partly covered end);
      ! a pair declared an interference fit takes an overlap of up to 1% of the slave group's
      ! extent (a strain of 1%: small strain), its negative gaps pressing the bodies apart
      tol = 1.0e-3_wp*hmean(sl)
      ext = norm2(maxval(ms%xy(:, mt%snode), dim=2) - minval(ms%xy(:, mt%snode), dim=2))
      if (cc%overlap == OVERLAP_INTERFERENCE) tol = 1.0e-2_wp*ext
      allocate (gdist(mt%m))
      do j = 1, mt%m
        gdist(j) = mt%g0(j)/sum(mt%sval(mt%sptr(j):mt%sptr(j + 1) - 1))
      end do
      gmin = minval(gdist)
      if (gmin < -tol) then
        j = minloc(gdist, dim=1)
        if (cc%overlap == OVERLAP_INTERFERENCE) then
          call err%set(ERR_INPUT, 'contact groups '''//trim(cc%body_group(1))//''' and '''// &
                trim(cc%body_group(2))//''' (overlap=''interference''): the overlap at slave node '// &
                i2s(ms%node_tag(mt%snode(j)))//' of body '//i2s(cc%bodies(sl))//' at ('// &
                sci(ms%xy(1, mt%snode(j)))//', '//sci(ms%xy(2, mt%snode(j)))//') is '//sci(-gmin)// &
                ', beyond 1% of the slave group''s extent '//sci(ext)//' (a strain beyond small strain, '// &
                'which this linear model does not cover); check the geometry')
        else
          call err%set(ERR_INPUT, 'contact groups '''//trim(cc%body_group(1))//''' and '''// &
                trim(cc%body_group(2))//''' overlap in the initial configuration: the gap at slave node '// &
                i2s(ms%node_tag(mt%snode(j)))//' of body '//i2s(cc%bodies(sl))//' at ('// &
                sci(ms%xy(1, mt%snode(j)))//', '//sci(ms%xy(2, mt%snode(j)))//') is '//sci(gmin)// &
                ' (tolerance '//sci(tol)//'); move the bodies apart, or, for a fit, give the pair '// &
                'overlap=''interference''')
        end if
        return
      end if

      ! a pair with friction (a positive bound) has NDIM - 1 tangential rows per slave node
      ! after the normal ones (tangent 1's, then tangent 2's), less those along a direction
      ! held on both sides (symmetry_tangents)
      itf%pair_friction = [FRICTION_NONE]
      if ((cc%friction == FRICTION_TRESCA .and. cc%slip_bound > 0.0_wp) .or. &
          (cc%friction == FRICTION_COULOMB .and. cc%mu > 0.0_wp)) itf%pair_friction = [cc%friction]
      allocate (keep_t(NDIM - 1, mt%m), nrm(NDIM, mt%m))
      keep_t = itf%pair_friction(1) /= FRICTION_NONE
      nrm = mt%normal
      if (itf%pair_friction(1) /= FRICTION_NONE .and. NDIM == 3) &
        call symmetry_tangents(sys(cc%bodies(sl)), sys(cc%bodies(ma)), mt, nrm, keep_t)
      nr = mt%m + count(keep_t)
      itf%m = nr
      allocate (itf%s(nr), itf%xy(NDIM, nr), itf%g0(nr), itf%trib(nr), itf%node(nr, 2), itf%frame(NDIM, NDIM, nr), &
                itf%dir(nr), itf%nrow(nr))
      itf%s(1:mt%m) = mt%s
      itf%xy(:, 1:mt%m) = ms%xy(:, mt%snode)
    end associate
    do j = 1, mt%m
      itf%frame(:, :, j) = frame_of(nrm(:, j))
    end do
    itf%trib(1:mt%m) = mt%d
    itf%node(1:mt%m, sl) = mt%snode
    itf%node(:, ma) = 0
    itf%g0(1:mt%m) = mt%g0
    if (cc%gap_radius > 0.0_wp) itf%g0(1:mt%m) = itf%g0(1:mt%m) + (itf%xy(1, 1:mt%m) - cc%gap_center)**2/ &
                                                  (2.0_wp*cc%gap_radius)
    itf%dir(1:mt%m) = DIR_NORMAL
    itf%nrow(1:mt%m) = [(j, j=1, mt%m)]
    r = mt%m
    do k = 1, NDIM - 1
      do j = 1, mt%m
        if (.not. keep_t(k, j)) cycle
        r = r + 1
        itf%s(r) = itf%s(j)
        itf%xy(:, r) = itf%xy(:, j)
        itf%frame(:, :, r) = itf%frame(:, :, j)
        itf%trib(r) = mt%d(j)
        itf%node(r, sl) = mt%snode(j)
        itf%g0(r) = 0.0_wp
        itf%dir(r) = k
        itf%nrow(r) = j
      end do
    end do
    ! B_s: + sum_k ws_k d_j.u_k ; B_m: - sum_l wm_l d_j.u_l (every component of each node),
    ! d_j the row's direction (normal, then tangents)
    ne = NCOMP*sum(mt%sptr(itf%nrow + 1) - mt%sptr(itf%nrow))
    allocate (itf%b(sl)%ptr(nr + 1), itf%b(sl)%dof(ne), itf%b(sl)%val(ne))
    ne = NCOMP*sum(mt%mptr(itf%nrow + 1) - mt%mptr(itf%nrow))
    allocate (itf%b(ma)%ptr(nr + 1), itf%b(ma)%dof(ne), itf%b(ma)%val(ne))
    call fill_rows(mt%sptr, mt%snod, mt%sval, 1.0_wp, itf%b(sl))
    call fill_rows(mt%mptr, mt%mnod, mt%mval, -1.0_wp, itf%b(ma))

  contains

    !> Rows of one side: each node entry (weight w) of slave node j gives sgn*w*d_r on each
    !! of its DOFs, d_r the direction of row r (j's normal, or its tangent k for r = j + k mt%m).
    subroutine fill_rows(ptr, nod, val, sgn, b)
      integer, intent(in) :: ptr(:), nod(:)
      real(wp), intent(in) :: val(:), sgn
      type(brows_t), intent(inout) :: b
      integer :: r, jj, kk, q, c
      real(wp) :: d(NDIM)
      q = 0
      b%ptr(1) = 1
      do r = 1, nr
        jj = itf%nrow(r)
        d = row_direction(itf, r)
        do kk = ptr(jj), ptr(jj + 1) - 1
          do c = 1, NCOMP
            q = q + 1
            b%dof(q) = node_dof(nod(kk), c)
            b%val(q) = sgn*val(kk)*d(c)
          end do
        end do
        b%ptr(r + 1) = q + 1
      end do
    end subroutine fill_rows

  end subroutine mortar_pair

  !> Friction in space on a plane of symmetry: where a slave node and some master node its row
  !! reaches have the same displacement component c prescribed (a roller on the plane x_c =
  !! const in both bodies) and the node's normal lies nearly in that plane (|n_c| < 0.1), the
  !! contact normal of the symmetric solution is in the plane: n_c is set to 0 (nrm), so that
  !! one tangent of the node's frame is e_c itself (frame_of), and that tangent's row is
  !! dropped (keep_t): the symmetric solution has no shear across the plane, and the row's
  !! force would act on the slave's prescribed DOF and use up the node's friction disc; the
  !! node keeps a tangential row in the plane, an interval as in 2D.
  subroutine symmetry_tangents(sys_s, sys_m, mt, nrm, keep_t)
    type(body_system_t), intent(in) :: sys_s, sys_m   !< the slave's and the master's body
    type(mortar_t), intent(in) :: mt
    real(wp), intent(inout) :: nrm(:, :)              !< (NDIM, m) the nodes' normals
    logical, intent(inout) :: keep_t(:, :)            !< (NDIM - 1, m) the tangential rows kept
    real(wp) :: f(NDIM, NDIM), e(NDIM)
    integer :: j, c, k, q
    logical :: held
    do j = 1, mt%m
      do c = 1, NCOMP
        if (abs(nrm(c, j)) >= 0.1_wp) cycle
        e = 0.0_wp
        e(c) = 1.0_wp
        ! held along e_c at the slave node, and at some master node its row reaches (the
        ! master's nodes off the plane also carry weights of a node at the plane's edge)
        held = normal_fixed(sys_s, mt%snode(j), e)
        if (held) held = any([(abs(mt%mval(q)) > 1.0e-12_wp .and. normal_fixed(sys_m, mt%mnod(q), e), &
                               q=mt%mptr(j), mt%mptr(j + 1) - 1)])
        if (.not. held) cycle
        nrm(c, j) = 0.0_wp
        nrm(:, j) = nrm(:, j)/norm2(nrm(:, j))
        f = frame_of(nrm(:, j))
        do k = 1, NDIM - 1
          if (abs(abs(f(c, k + 1)) - 1.0_wp) <= 1.0e-12_wp) keep_t(k, j) = .false.
        end do
      end do
    end do
  end subroutine symmetry_tangents

  !> Whether the displacement of node k along nrm is prescribed in the body: every
  !! component that nrm has is a prescribed DOF.
  pure logical function normal_fixed(sys, k, nrm)
    type(body_system_t), intent(in) :: sys
    integer, intent(in) :: k
    real(wp), intent(in) :: nrm(NDIM)
    integer :: c
    normal_fixed = .true.
    do c = 1, NCOMP
      if (abs(nrm(c)) > 1.0e-12_wp .and. sys%free_of(node_dof(k, c)) > 0) normal_fixed = .false.
    end do
  end function normal_fixed

end module contact_interface
