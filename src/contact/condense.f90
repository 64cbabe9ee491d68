!> Interface condensation: the contact interface of the two bodies (its m constraint rows
!! B_1 u_1 + B_2 u_2 <= g0), and for each body its factorization, normal flexibility
!! F_a = B_a K_a^-1 B_a' and the normal interface displacement under the load alone
!! b_a = B_a K_a^-1 f_a (plus B_a's part on prescribed DOFs) (doc/method.md). The rows come
!! from two edge groups (named groups, or the rectangle sides declared 'contact') paired by
!! dual mortar (module mortar; row j = the weighted normal gap at slave node j). The free DOFs
!! that B_a touches are ordered last in the Cholesky factorization, so F_a comes from the
!! trailing block of the factor at a cost of O(k^3) (k those DOFs), not m solves.
module condense
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use config, only: body_cfg_t, contact_cfg_t, factor_cfg_t, BC_CONTACT, side_names, &
                    FACTOR_BANDED, ORDER_AMD, ORDER_NATURAL, ORDER_ND
  use mesh, only: mesh_t, group_index, group_names, nodes_only, nodes_only_refusal
  use mortar, only: mortar_t, mortar_build
  use strings, only: i2s, r2s
  use assembly, only: body_system_t
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN
  use ordering, only: grid_dissection, coordinate_bisection
  use clock, only: wtime
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL, ERR_MEMORY
  use lapack, only: dpstrf, dsyev
  implicit none (type, external)
  private

  !> The m rows of one body's B_a (compressed rows over global DOFs 2*(node-1)+c).
  type, public :: brows_t
    integer, allocatable :: ptr(:)          !< (m+1) row k is entries ptr(k) .. ptr(k+1)-1
    integer, allocatable :: dof(:)          !< global DOF of each entry
    real(wp), allocatable :: val(:)         !< coefficient of each entry [-]
  end type brows_t

  !> The contact interface: m constraint rows, one per contact node of the slave side.
  type, public :: interface_t
    integer :: m = 0                        !< contact constraints (slave nodes with a multiplier)
    logical :: mortar = .false.             !< rows from dual mortar on named groups
    integer :: slave = 1                    !< body whose nodes carry the rows
    real(wp), allocatable :: s(:)           !< (m) arc length along the slave contact chain [length]
    real(wp), allocatable :: xy(:, :)       !< (2,m) slave node coordinates [length]
    real(wp), allocatable :: normal(:, :)   !< (2,m) unit normal, outward from the slave body
    real(wp), allocatable :: g0(:)          !< (m) initial normal gap [length]
    real(wp), allocatable :: trib(:)        !< (m) tributary length D_jj [length]
    integer, allocatable :: node(:, :)      !< (m,2) mesh node of each body (0: none, mortar master)
    type(brows_t) :: b(2)                   !< B_1, B_2
  end type interface_t

  !> One body reduced to the interface.
  type, public :: body_condensed_t
    integer :: m = 0                        !< interface size
    integer :: n = 0                        !< free DOFs of the body
    integer, allocatable :: idx(:)          !< (k) the free DOFs B_a touches, ordered last
    integer, allocatable :: bptr(:)         !< (m+1) B_a on them: row i is entries bptr(i)..bptr(i+1)-1,
    integer, allocatable :: bpos(:)         !<   position in idx of each entry
    real(wp), allocatable :: bval(:)        !<   and its coefficient
    real(wp), allocatable :: bfix(:)        !< (m) B_a's part on prescribed DOFs, B_a,d u_d [length]
    real(wp), allocatable :: flex(:, :)     !< (m,m) F_a [length/force]
    !> > 0 when F_a is singular (mortar: a master surface coarser than the slave has fewer
    !! normal DOFs than the slave has rows): then the body's subproblem gets a proximal term
    !! that pins its multipliers to the other body's (robin_operators `proximal_term`);
    !! its value, 1e-2 max diag F_a, is the scale of F_a
    real(wp) :: prox = 0.0_wp             !< [length/force]
    integer :: rank = 0                   !< numerical rank of F_a
    !> (m, m - rank) orthonormal basis Z of the numerical kernel of F_a (unallocated when F_a
    !! is nonsingular): the proximal term and the obstacle act on Z Z' only (robin_operators)
    real(wp), allocatable :: kern(:, :)
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
    real(wp), allocatable :: u0(:)          !< (n) K_a^-1 f_a [length]
    type(chol_t) :: chol                    !< the factorization of K_a
    real(wp) :: t_factor = 0.0_wp           !< wall time of analyze + factorize [s]
    real(wp) :: t_condense = 0.0_wp         !< wall time of F_a and b_a [s]
  end type body_condensed_t

  public :: build_interface, factor_body, condense_body, recover_displacement, apply_bt, apply_b, &
            interface_dofs, flex_from_x, contact_resultant

contains

  !> The resultant of the contact forces on body a, -sum of B_a' lam by component [force]:
  !! what balances the body's applied load when contact alone holds it (the sum of the
  !! nodal normal forces is not a resultant on a curved contact line).
  pure function contact_resultant(itf, a, lam) result(f)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a                  !< body
    real(wp), intent(in) :: lam(:)            !< (m) contact forces [force]
    real(wp) :: f(2)
    integer :: k, e, c
    f = 0.0_wp
    do k = 1, itf%m
      do e = itf%b(a)%ptr(k), itf%b(a)%ptr(k + 1) - 1
        c = 2 - mod(itf%b(a)%dof(e), 2)
        f(c) = f(c) - itf%b(a)%val(e)*lam(k)
      end do
    end do
  end function contact_resultant

  !> The contact interface of the two bodies, by dual mortar on two edge groups: the named
  !! groups of &contact, or a rectangle's side declared 'contact' (its mesh has the sides
  !! as groups 'left', 'right', 'bottom', 'top'). On matching lines the mortar rows are the
  !! node-to-node ones to rounding, so one path serves every scene.
  subroutine build_interface(body, cc, msh, sys, itf, err)
    type(body_cfg_t), intent(in) :: body(2)          !< the two bodies (their contact sides)
    type(contact_cfg_t), intent(in) :: cc            !< the interface settings (groups, slave, initial gap)
    type(mesh_t), intent(in) :: msh(2)               !< meshes of body 1 and 2
    type(body_system_t), intent(in) :: sys(2)        !< assembled systems
    type(interface_t), intent(out) :: itf            !< the contact line
    type(error_t), intent(out) :: err                !< the bad input (ERR_INPUT), if any
    type(contact_cfg_t) :: ccg
    integer :: a, side

    ccg = cc
    if (len_trim(cc%body_group(1)) == 0) then
      do a = 1, 2
        side = findloc(body(a)%bc, BC_CONTACT, dim=1)
        if (side == 0) then
          call err%set(ERR_INPUT, 'body '//i2s(a)//' has no contact side')
          return
        end if
        ccg%body_group(a) = side_names(side)
      end do
    end if
    call mortar_interface(ccg, msh, sys, itf, err)
  end subroutine build_interface

  !> The interface of two named edge groups by dual mortar (module mortar): the slave is
  !! cc%slave, or the body whose contact group has the shorter mean edge (body 1 on a tie).
  !! A slave node carries no row when its normal displacement and that of every master node
  !! its row involves are prescribed (the constraint would only repeat the supports): found
  !! by a first build, then the rows are built again without those nodes. err = ERR_INPUT
  !! for an unknown group, a group facing nothing, or an initial overlap.
  subroutine mortar_interface(cc, msh, sys, itf, err)
    type(contact_cfg_t), intent(in) :: cc
    type(mesh_t), intent(in) :: msh(2)
    type(body_system_t), intent(in) :: sys(2)
    type(interface_t), intent(out) :: itf
    type(error_t), intent(out) :: err
    integer :: g(2), a, sl, ma, j, e, k, ne
    real(wp) :: hmean(2), tol, gmin
    logical, allocatable :: removable(:)
    real(wp), allocatable :: gdist(:)
    type(mortar_t) :: mt
    type(error_t) :: why

    do a = 1, 2
      g(a) = group_index(msh(a), cc%body_group(a))
      if (g(a) == 0) then
        call err%set(ERR_INPUT, '&contact body'//i2s(a)//'_group='''//trim(cc%body_group(a))//''': body '//i2s(a)// &
              ' has no such group with edges on its boundary; its groups are '//group_names(msh(a)))
        return
      end if
      if (nodes_only(msh(a), g(a))) then
        call err%set(ERR_INPUT, '&contact body'//i2s(a)//'_group='''//trim(cc%body_group(a))//''': body '//i2s(a)//': '// &
              nodes_only_refusal(msh(a), g(a), 'contact needs'))
        return
      end if
      associate (gr => msh(a)%group(g(a)))
        hmean(a) = 0.0_wp
        do e = 1, gr%nedge
          hmean(a) = hmean(a) + norm2(msh(a)%xy(:, gr%edge(2, e)) - msh(a)%xy(:, gr%edge(1, e)))
        end do
        hmean(a) = hmean(a)/max(1, gr%nedge)
      end associate
    end do
    sl = cc%slave
    if (sl == 0) sl = merge(2, 1, hmean(2) < hmean(1)*(1.0_wp - 1.0e-12_wp))
    ma = 3 - sl
    itf%mortar = .true.
    itf%slave = sl

    allocate (removable(msh(sl)%nnode))
    removable = .false.
    call mortar_build(msh(sl)%xy, msh(sl)%group(g(sl))%edge, removable, msh(ma)%xy, &
                      msh(ma)%group(g(ma))%edge, mt, why)
    if (.not. why%failed()) then
      do j = 1, mt%m
        removable(mt%snode(j)) = normal_fixed(sys(sl), mt%snode(j), mt%normal(:, j))
        do k = mt%mptr(j), mt%mptr(j + 1) - 1
          if (abs(mt%mval(k)) > 1.0e-12_wp) removable(mt%snode(j)) = removable(mt%snode(j)) .and. &
            normal_fixed(sys(ma), mt%mnod(k), mt%normal(:, j))
        end do
      end do
      if (any(removable)) call mortar_build(msh(sl)%xy, msh(sl)%group(g(sl))%edge, removable, msh(ma)%xy, &
                                            msh(ma)%group(g(ma))%edge, mt, why)
    end if
    if (why%failed()) then
      call err%set(ERR_INPUT, 'contact group '''//trim(cc%body_group(sl))//''' of body '//i2s(sl)//' (slave) and '''// &
                   trim(cc%body_group(ma))//''' of body '//i2s(ma)//' (master): '//why%text())
      return
    end if

    ! an initial overlap beyond a thousandth of the slave's mean edge is bad input
    ! (the gap of a row divided by its slave weight sum: the distance, where the row's
    ! weights sum to more or less than one next to a removed node or at a partly covered end)
    tol = 1.0e-3_wp*hmean(sl)
    allocate (gdist(mt%m))
    do j = 1, mt%m
      gdist(j) = mt%g0(j)/sum(mt%sval(mt%sptr(j):mt%sptr(j + 1) - 1))
    end do
    gmin = minval(gdist)
    if (gmin < -tol) then
      j = minloc(gdist, dim=1)
      call err%set(ERR_INPUT, 'contact groups '''//trim(cc%body_group(1))//''' and '''//trim(cc%body_group(2))// &
            ''' overlap in the initial configuration: the gap at slave node '//i2s(msh(sl)%node_tag(mt%snode(j)))// &
            ' of body '//i2s(sl)//' at ('//r2s(msh(sl)%xy(1, mt%snode(j)))//', '//r2s(msh(sl)%xy(2, mt%snode(j)))// &
            ') is '//r2s(gmin)//' (tolerance '//r2s(tol)//'); move the bodies apart')
      return
    end if

    itf%m = mt%m
    allocate (itf%s(mt%m), itf%xy(2, mt%m), itf%g0(mt%m), itf%trib(mt%m), itf%node(mt%m, 2), &
              itf%normal(2, mt%m))
    itf%s = mt%s
    itf%xy = msh(sl)%xy(:, mt%snode)
    itf%normal = mt%normal
    itf%trib = mt%d
    itf%node(:, sl) = mt%snode
    itf%node(:, ma) = 0
    itf%g0 = mt%g0
    if (cc%gap_radius > 0.0_wp) itf%g0 = itf%g0 + (itf%xy(1, :) - cc%gap_center)**2/(2.0_wp*cc%gap_radius)
    ! B_s: + sum_k ws_k n_j.u_k ; B_m: - sum_l wm_l n_j.u_l (both components of each node)
    ne = 2*(mt%sptr(mt%m + 1) - 1)
    allocate (itf%b(sl)%ptr(mt%m + 1), itf%b(sl)%dof(ne), itf%b(sl)%val(ne))
    ne = 2*(mt%mptr(mt%m + 1) - 1)
    allocate (itf%b(ma)%ptr(mt%m + 1), itf%b(ma)%dof(ne), itf%b(ma)%val(ne))
    call fill_rows(mt%sptr, mt%snod, mt%sval, 1.0_wp, itf%b(sl))
    call fill_rows(mt%mptr, mt%mnod, mt%mval, -1.0_wp, itf%b(ma))

  contains

    !> Rows of one body: each node entry (weight w) gives sgn*w*n_j on both its DOFs.
    subroutine fill_rows(ptr, nod, val, sgn, b)
      integer, intent(in) :: ptr(:), nod(:)
      real(wp), intent(in) :: val(:), sgn
      type(brows_t), intent(inout) :: b
      integer :: jj, kk, q, c
      q = 0
      b%ptr(1) = 1
      do jj = 1, mt%m
        do kk = ptr(jj), ptr(jj + 1) - 1
          do c = 1, 2
            q = q + 1
            b%dof(q) = 2*(nod(kk) - 1) + c
            b%val(q) = sgn*val(kk)*mt%normal(c, jj)
          end do
        end do
        b%ptr(jj + 1) = q + 1
      end do
    end subroutine fill_rows

  end subroutine mortar_interface

  !> Whether the displacement of node k along nrm is prescribed in the body: every
  !! component that nrm has is a prescribed DOF.
  pure logical function normal_fixed(sys, k, nrm)
    type(body_system_t), intent(in) :: sys
    integer, intent(in) :: k
    real(wp), intent(in) :: nrm(2)
    integer :: c
    normal_fixed = .true.
    do c = 1, 2
      if (abs(nrm(c)) > 1.0e-12_wp .and. sys%free_of(2*(k - 1) + c) > 0) normal_fixed = .false.
    end do
  end function normal_fixed


  !> B_a on the free DOFs of body a: the DOFs it touches with a non-zero coefficient, in the
  !! order the rows first touch them (these are ordered last in the factorization), the
  !! rows over their positions, and the constant part on prescribed DOFs.
  subroutine interface_dofs(itf, a, sys, bc)
    type(interface_t), intent(in) :: itf             !< the contact line
    integer, intent(in) :: a                         !< body number
    type(body_system_t), intent(in) :: sys           !< assembled system of body a
    type(body_condensed_t), intent(inout) :: bc      !< receives m, n, idx and the rows on it
    integer :: i, e, p, k, ne
    integer, allocatable :: pos_of(:), idx(:)

    bc%m = itf%m
    bc%n = sys%n
    if (allocated(bc%idx)) deallocate (bc%idx)
    if (allocated(bc%bptr)) deallocate (bc%bptr, bc%bpos, bc%bval, bc%bfix)
    associate (b => itf%b(a))
      ne = b%ptr(itf%m + 1) - 1
      allocate (pos_of(sys%n), idx(ne), bc%bptr(itf%m + 1), bc%bpos(ne), bc%bval(ne), bc%bfix(itf%m))
      pos_of = 0
      k = 0
      ne = 0
      bc%bptr(1) = 1
      do i = 1, itf%m
        bc%bfix(i) = 0.0_wp
        do e = b%ptr(i), b%ptr(i + 1) - 1
          if (b%val(e) == 0.0_wp) cycle
          p = sys%free_of(b%dof(e))
          if (p == 0) then
            bc%bfix(i) = bc%bfix(i) + b%val(e)*sys%u_fixed(b%dof(e))
            cycle
          end if
          if (pos_of(p) == 0) then
            k = k + 1
            idx(k) = p
            pos_of(p) = k
          end if
          ne = ne + 1
          bc%bpos(ne) = pos_of(p)
          bc%bval(ne) = b%val(e)
        end do
        bc%bptr(i + 1) = ne + 1
      end do
    end associate
    bc%idx = idx(1:k)
  end subroutine interface_dofs

  !> Factorize K_a with the interface DOFs ordered last. ordering='nd' orders the
  !! other DOFs by geometric nested dissection of the body's grid (module ordering);
  !! its time is part of t_factor.
  subroutine factor_body(fc, itf, a, msh, sys, bc, err)
    type(factor_cfg_t), intent(in) :: fc             !< factorization and ordering
    type(interface_t), intent(in) :: itf             !< the contact line
    integer, intent(in) :: a                         !< body number
    type(mesh_t), intent(in) :: msh                  !< mesh of body a
    type(body_system_t), intent(in) :: sys           !< assembled system of body a
    type(body_condensed_t), intent(inout) :: bc      !< receives the factorization
    type(error_t), intent(out) :: err                !< the failure (see chol_factor), if any
    integer :: method, iord
    integer, allocatable :: perm(:)
    real(wp) :: t0

    t0 = wtime()
    call interface_dofs(itf, a, sys, bc)
    ! the deck's choice as the Cholesky module's method and ordering ('nd' is our own
    ! permutation of the interior, given to CHOLMOD)
    method = merge(FACT_BANDED, FACT_CHOLMOD, fc%factorization == FACTOR_BANDED)
    select case (fc%ordering)
    case (ORDER_AMD)
      iord = ORD_AMD
    case (ORDER_NATURAL)
      iord = ORD_NATURAL
    case (ORDER_ND)
      iord = ORD_GIVEN
    case default
      iord = ORD_METIS
    end select
    if (iord == ORD_GIVEN .and. method == FACT_CHOLMOD) then
      if (msh%structured) then
        call grid_dissection(msh%nx, msh%ny, sys%free_of, sys%n, bc%idx, perm, err)
      else
        call coordinate_bisection(msh%xy, sys%free_of, sys%dof_of, sys%colptr, sys%rowind, bc%idx, perm, err)
      end if
      if (err%failed()) then
        bc%t_factor = wtime() - t0
        return
      end if
      call bc%chol%factor(sys%n, sys%colptr, sys%rowind, sys%val, method, iord, err, last=bc%idx, &
                          interior_perm=perm)
    else
      call bc%chol%factor(sys%n, sys%colptr, sys%rowind, sys%val, method, iord, err, last=bc%idx)
    end if
    bc%t_factor = wtime() - t0
  end subroutine factor_body

  !> Form F_a and b_a (and u0 = K_a^-1 f_a) from the factorization.
  subroutine condense_body(sys, bc, err)
    type(body_system_t), intent(in) :: sys           !< assembled system of the body
    type(body_condensed_t), intent(inout) :: bc      !< factorized body; receives flex, b, u0
    type(error_t), intent(out) :: err                !< the failure, if any
    real(wp) :: t0
    integer :: k, st
    real(wp), allocatable :: x(:, :)
    t0 = wtime()
    if (allocated(bc%flex)) deallocate (bc%flex)
    if (allocated(bc%b)) deallocate (bc%b)
    if (allocated(bc%u0)) deallocate (bc%u0)
    allocate (bc%b(bc%m), bc%u0(sys%n))
    k = size(bc%idx)
    if (bc%m > 0 .and. k > 0) then
      ! X = (K^-1) on the interface DOFs, then F = B X B' over the few entries of each row
      allocate (x(k, k), stat=st)
      if (st /= 0) then
        call err%set(ERR_MEMORY, 'out of memory for the interface block of K^-1')
        return
      end if
      call bc%chol%flexibility(bc%idx, spread(1.0_wp, 1, k), x, err)
      if (err%failed()) return
    end if
    if (.not. allocated(x)) allocate (x(0, 0))
    call flex_from_x(bc, x)
    bc%u0 = sys%f
    call bc%chol%solve(bc%u0, err)
    if (err%failed()) return
    call apply_b(bc, bc%u0, bc%b)
    bc%t_condense = wtime() - t0
  end subroutine condense_body

  !> F_a = B_a X B_a' from X = (K_a^-1) on the interface DOFs bc%idx (any factorization:
  !! CHOLMOD's trailing block or MUMPS's inverse Schur complement), over the few entries of
  !! each row; then F_a's numerical rank and the proximal weight (flex_rank).
  subroutine flex_from_x(bc, x)
    type(body_condensed_t), intent(inout) :: bc      !< body with its rows; receives flex, rank, prox
    real(wp), intent(in) :: x(:, :)                  !< (k,k) (K_a^-1) on bc%idx [length/force]
    integer :: i, j, e, f
    real(wp) :: acc
    if (allocated(bc%flex)) deallocate (bc%flex)
    allocate (bc%flex(bc%m, bc%m))
    if (bc%m > 0) bc%flex = 0.0_wp
    if (bc%m > 0 .and. size(bc%idx) > 0) then
      do j = 1, bc%m
        do i = 1, bc%m
          acc = 0.0_wp
          do f = bc%bptr(j), bc%bptr(j + 1) - 1
            do e = bc%bptr(i), bc%bptr(i + 1) - 1
              acc = acc + (bc%bval(e)*bc%bval(f))*x(bc%bpos(e), bc%bpos(f))
            end do
          end do
          bc%flex(i, j) = acc
        end do
      end do
    end if
    bc%rank = bc%m
    bc%prox = 0.0_wp
    if (bc%m > 0 .and. .not. selection_rows(bc)) call flex_rank(bc)
  end subroutine flex_from_x

  !> True when every row of B_a picks one DOF, each a different one (F_a is then a principal
  !! block of K_a^-1 up to signs, positive definite).
  pure logical function selection_rows(bc)
    type(body_condensed_t), intent(in) :: bc
    selection_rows = size(bc%idx) == bc%m .and. size(bc%bpos) == bc%m
  end function selection_rows

  !> The numerical rank of F_a by Cholesky with complete pivoting (pivots below
  !! 1e-10 max diag stop it); when it is rank deficient, `prox` is a hundredth of its
  !! largest diagonal entry and `kern` an orthonormal basis of the kernel:
  !! the eigenvectors of the m - rank smallest eigenvalues (LAPACK dsyev, once, O(m^3)).
  !! F_a = 0 (all its contact DOFs prescribed): rank 0, no `kern` (the proximal term is then
  !! the other body's F).
  subroutine flex_rank(bc)
    type(body_condensed_t), intent(inout) :: bc
    real(wp), allocatable :: f(:, :), work(:), ev(:)
    integer, allocatable :: piv(:)
    integer :: lapinfo, r, lwork
    real(wp) :: dmax
    integer :: i
    dmax = 0.0_wp
    do i = 1, bc%m
      dmax = max(dmax, bc%flex(i, i))
    end do
    if (.not. dmax > 0.0_wp) then
      ! every contact DOF of the body is prescribed (a foundation drawn as a body): F_a = 0,
      ! its kernel is everything, and the proximal term alone (the other body's F) carries
      ! its subproblem: the other body then solves the obstacle problem against it
      bc%rank = 0
      bc%prox = 1.0_wp
      return
    end if
    allocate (f(bc%m, bc%m), work(2*bc%m), piv(bc%m))
    f = bc%flex
    call dpstrf('L', bc%m, f, bc%m, piv, r, 1.0e-10_wp*dmax, work, lapinfo)
    if (lapinfo < 0) return
    bc%rank = r
    if (r == bc%m) return
    bc%prox = 1.0e-2_wp*dmax
    f = bc%flex
    allocate (ev(bc%m))
    call dsyev('V', 'L', bc%m, f, bc%m, ev, work, -1, lapinfo)
    lwork = max(3*bc%m, int(work(1)))
    deallocate (work)
    allocate (work(lwork))
    call dsyev('V', 'L', bc%m, f, bc%m, ev, work, lwork, lapinfo)
    ! no eigenvectors (dsyev did not converge): robin_operators then uses the other body's F
    if (lapinfo == 0) bc%kern = f(:, 1:bc%m - r)
  end subroutine flex_rank

  !> w(m) = B_a u: the rows on the free displacements u (n) plus the part on prescribed DOFs.
  subroutine apply_b(bc, u, w)
    type(body_condensed_t), intent(in) :: bc         !< condensed body
    real(wp), intent(in) :: u(:)                     !< (n) free displacements [length]
    real(wp), intent(out) :: w(:)                    !< (m) B_a u [length]
    integer :: i, e
    do i = 1, bc%m
      w(i) = 0.0_wp
      do e = bc%bptr(i), bc%bptr(i + 1) - 1
        w(i) = w(i) + bc%bval(e)*u(bc%idx(bc%bpos(e)))
      end do
      w(i) = w(i) + bc%bfix(i)
    end do
  end subroutine apply_b

  !> r(n) = B_a' lam: scatter the interface forces onto the normal DOFs.
  subroutine apply_bt(bc, lam, r)
    type(body_condensed_t), intent(in) :: bc         !< condensed body
    real(wp), intent(in) :: lam(:)                   !< (m) interface forces [force]
    real(wp), intent(inout) :: r(:)                  !< (n) r += B_a' lam
    integer :: i, e
    do i = 1, bc%m
      do e = bc%bptr(i), bc%bptr(i + 1) - 1
        r(bc%idx(bc%bpos(e))) = r(bc%idx(bc%bpos(e))) + bc%bval(e)*lam(i)
      end do
    end do
  end subroutine apply_bt

  !> u_free = K_a^-1 (f_a - B_a' lam): the body's displacement under its load and
  !! the contact forces lam (one solve).
  subroutine recover_displacement(sys, bc, lam, u_free)
    type(body_system_t), intent(in) :: sys           !< assembled system
    type(body_condensed_t), intent(inout) :: bc      !< factorized body
    real(wp), intent(in) :: lam(:)                   !< (m) contact force on this body [force]
    real(wp), intent(out) :: u_free(:)               !< (n) displacement at free DOFs [length]
    real(wp), allocatable :: r(:)
    type(error_t) :: err
    allocate (r(sys%n))
    r = 0.0_wp
    call apply_bt(bc, lam, r)
    call bc%chol%solve(r, err)
    if (err%failed()) r = ieee_value(1.0_wp, ieee_quiet_nan)
    u_free = bc%u0 - r
  end subroutine recover_displacement

end module condense
