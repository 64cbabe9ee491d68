!> How a run ends: its exit code from the contact status (with the reason and the next
!! setting to try on standard error) and the closing summary lines on standard output.
module run_summary
  use kinds, only: wp
  use space, only: NDIM, NCOMP, node_dof, dof_comp
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64
  use errors, only: EXIT_OK, EXIT_NOT_CONVERGED, EXIT_NUMERICAL, EXIT_INTERRUPTED, warn
  use config, only: side_axis, MAX_SIDES, solver_cfg_t, ROBIN_HARMONIC, FRICTION_TRESCA, BC_CLAMPED, BC_ROLLER, BC_DISPLACEMENT, side_names, METHOD_MONOLITHIC, METHOD_CHOICES
  use contact_interface, only: interface_t, DIR_NORMAL, contact_resultant
  use contact_types, only: contact_result_t
  use friction_view, only: tangential_t, split_friction, NODE_STICK, NODE_SLIP
  use contact_types, only: status_name, STATUS_CONVERGED, STATUS_FAILED, STATUS_INTERRUPTED, STATUS_NO_EQUILIBRIUM
  use sysinfo, only: write_stdout_checked
  use strings, only: sci, fixed, i2s, word
  use run_state, only: run_t
  use mesh, only: group_index, group_nodes
  use namelist_vars, only: str_t
  use condense, only: apply_bt, to_global
  use contact_common, only: gather
  implicit none (type, external)
  private

  public :: set_exit_code, summary, step_line, print_assembled

  !> Bodies listed on the `bodies:` line, pairs on a `step:` line (the rest counted).
  integer, parameter :: MAX_LISTED = 20
  !> the most pairs whose resultant a step: line shows (it stays under 600 characters)
  integer, parameter :: MAX_STEP_RESULTANTS = 6

contains

  !> The exit code of the contact status; a run that did not converge says why, and what
  !! to try next, on standard error.
  subroutine set_exit_code(run)
    type(run_t), intent(inout) :: run   !< the run: its result's status, its code
    select case (run%result%status)
    case (STATUS_CONVERGED)
      run%code = EXIT_OK
    case (STATUS_FAILED)
      run%code = EXIT_NUMERICAL
    case (STATUS_INTERRUPTED)
      run%code = EXIT_INTERRUPTED
    case default
      run%code = EXIT_NOT_CONVERGED
    end select
    if (run%result%status /= STATUS_CONVERGED) write (error_unit, '(a)') 'robin_contact: '// &
      status_name(run%result%status)//': '//trim(run%result%message)
    if (run%result%status == STATUS_CONVERGED .and. len_trim(run%result%message) > 0 .and. run%rank == 0) &
      write (error_unit, '(a)') 'robin_contact: note: '//trim(run%result%message)
    if (run%code == EXIT_NOT_CONVERGED .and. run%result%status /= STATUS_NO_EQUILIBRIUM) write (error_unit, '(a)') &
      'robin_contact: next: '//next_setting(run%deck%solver, run%result%method == METHOD_MONOLITHIC)
    if (run%result%status == STATUS_NO_EQUILIBRIUM) write (error_unit, '(a)') 'robin_contact: next: the steps '// &
      'before it are solved and written; no solver setting gives a step without an equilibrium one: lower its '// &
      'loads, raise mu, or support the body'
  end subroutine set_exit_code

  !> The closing lines (rank 0). A summary that cannot be written (standard output on a
  !! full disk or a closed pipe) is a failure, exit 3: scripts read the result: line.
  subroutine summary(run)
    type(run_t), intent(inout) :: run   !< the run: its result and timing; its code on failure
    character(len=1024) :: line(5)
    character(len=1024), allocatable :: pairs(:), reactions(:)
    integer :: err(5), k
    if (run%rank /= 0) return
    associate (result => run%result, timing => run%timing)
      err = 0
      pairs = pair_lines(run)
      reactions = reaction_lines(run)
      if (result%outer > 0 .and. result%error_bound < 1.0_wp) then
        line(2) = 'accuracy: |lam - lam_monolithic|/|lam| <= '//sci(result%error_bound)// &
          ' (a posteriori bound, cond('//trim(merge('F1+F2', 'H    ', run%contact_line%npair <= 1))//') ~ '//sci(result%kappa)//')'
      else if (result%outer > 0 .and. len_trim(result%no_bound_reason) > 0) then
        line(2) = 'accuracy: no bound ('//trim(result%no_bound_reason)//')'
      else if (result%outer > 0) then
        ! a relative error bound of 1 or more says nothing: say why instead
        line(2) = 'accuracy: no bound (the a posteriori bound is '//sci(result%error_bound)//', cond('// &
          trim(merge('F1+F2', 'H    ', run%contact_line%npair <= 1))//') ~ '//sci(result%kappa)
        if (result%kappa > 1.0_wp/epsilon(1.0_wp)) then
          line(2) = trim(line(2))//': the interface problem is singular, a force the equations leave free, '// &
                    'such as on a row of prescribed DOFs only)'
        else if (result%natural >= 0.0_wp) then
          ! what is known: how far the forces are from satisfying the monolithic problem's
          ! optimality conditions (the bound multiplies it by 2 cond)
          line(2) = trim(line(2))//': it says nothing about these forces); their natural residual '// &
                    '|lam - P(lam - grad/L)|/|lam| = '//sci(result%natural)//' (zero at the monolithic solution)'
        else
          line(2) = trim(line(2))//': it says nothing about these forces)'
        end if
      else
        line(2) = 'accuracy: none (stopped before the first outer iteration: no contact forces to bound)'
      end if
      write (line(3), '(a,6(a,f0.3),a,f0.1,a,f0.1)') 'time:', ' assemble=', timing%assemble, ' factor=', timing%factor, &
        ' condense=', timing%condense, ' iterate=', timing%iterate, ' output=', timing%output, ' total=', timing%total, &
        ' peak_mb=', timing%peak_rss_mb, ' factor_mb=', timing%factor_mb
      write (line(4), '(a,a,a,a,a,i0,a,i0,a,i0,a,i0,a,i0,a,a,a,es8.2,a,a)') 'result: status=', &
        status_name(result%status), ' method=', word(METHOD_CHOICES, result%method), ' outer=', result%outer, ' inner=', result%inner, &
        ' n1=', run%systems(1)%n, ' n2=', run%systems(2)%n, ' m=', run%contact_line%m, &
        ' delta=', fixed(run%deck%solver%delta, '(f0.6)'), ' residual=', result%residual, &
        ' wall_s=', fixed(timing%total, '(f0.3)')
      line(4) = trim(line(4))//' bodies='//i2s(run%nbody)//' pairs='//i2s(run%contact_line%npair)// &
                ' dofs='//total_dofs(run)
      ! one contact line per pair; the output line sits before the time line when a result
      ! file was written
      do k = 1, size(pairs)
        call write_stdout_checked(trim(pairs(k)), err(1))
        if (err(1) /= 0) exit
      end do
      do k = 1, size(reactions)
        if (err(1) /= 0) exit
        call write_stdout_checked(trim(reactions(k)), err(1))
      end do
      do k = 2, 4
        if (k == 3 .and. run%written) then
          call write_stdout_checked('output: '//trim(run%deck%output%file), err(5))
        end if
        call write_stdout_checked(trim(line(k)), err(k))
      end do
      if (any(err /= 0)) then
        write (error_unit, '(a)') 'robin_contact: error: cannot write the summary to standard output '// &
          '(full disk or closed pipe?); the run''s status was '//status_name(result%status)
        run%code = EXIT_NUMERICAL
      end if
    end associate
  end subroutine summary

  !> The `step:` line of load step k: its stage, load factor, outer iterations, status
  !! and the sum of the nodal normal contact forces of all pairs; with several pairs, each
  !! pair's own sum too (the first MAX_LISTED pairs, then how many more).
  function step_line(run, k) result(t)
    type(run_t), intent(in) :: run   !< the run: its plan and current result
    integer, intent(in) :: k         !< the step
    character(len=:), allocatable :: t
    real(wp) :: ftot, f2(NCOMP)
    integer :: p, np
    ftot = 0.0_wp
    if (allocated(run%result%lam)) then
      ftot = sum(run%result%lam)
      if (allocated(run%contact_line%dir)) ftot = sum(run%result%lam, mask=run%contact_line%dir == DIR_NORMAL)
    end if
    t = 'step: step='//i2s(k)//' of='//i2s(size(run%plan))//' stage='//i2s(run%plan(k)%stage)// &
        ' load_factor='//fixed(run%plan(k)%factor, '(f0.6)')//' outer='//i2s(run%result%outer)// &
        ' status='//status_name(run%result%status)//' normal_force_sum='//sci(ftot, 5)
    np = run%contact_line%npair
    if (np > 1 .and. allocated(run%contact_line%pair_ptr)) then
      t = t//' pair_normal_force_sum='
      do p = 1, min(np, MAX_LISTED)
        if (p > 1) t = t//','
        t = t//sci(pair_normal_sum(run, p), 5)
      end do
      if (np > MAX_LISTED) t = t//' more_pairs='//i2s(np - MAX_LISTED)
    end if
    ! the contact resultant (normal and tangential forces) of each pair on its first body,
    ! fx:fy, for the first MAX_STEP_RESULTANTS pairs (the result file has every pair's)
    if (allocated(run%result%lam) .and. allocated(run%contact_line%pair_ptr) .and. np >= 1) then
      t = t//' pair_resultant='
      do p = 1, min(np, MAX_STEP_RESULTANTS)
        if (p > 1) t = t//','
        f2 = contact_resultant(run%contact_line, 1, run%result%lam, run%contact_line%pair_ptr(p), &
                               min(run%contact_line%pair_ptr(p + 1) - 1, size(run%result%lam)))
        t = t//vec_text(f2, ':', 4)
      end do
      if (np > MAX_STEP_RESULTANTS) t = t//',...'
    end if
  end function step_line

  !> The sum of pair p's nodal normal contact forces (0 before any result).
  function pair_normal_sum(run, p) result(f)
    type(run_t), intent(in) :: run
    integer, intent(in) :: p   !< the pair
    real(wp) :: f
    integer :: r1, r2
    f = 0.0_wp
    if (.not. allocated(run%result%lam)) return
    r1 = run%contact_line%pair_ptr(p)
    r2 = min(run%contact_line%pair_ptr(p + 1) - 1, size(run%result%lam))
    if (r2 < r1) return
    if (allocated(run%contact_line%dir)) then
      f = sum(run%result%lam(r1:r2), mask=run%contact_line%dir(r1:r2) == DIR_NORMAL)
    else
      f = sum(run%result%lam(r1:r2))
    end if
  end function pair_normal_sum

  !> The DOFs of all bodies (after the supports), as text.
  function total_dofs(run) result(t)
    type(run_t), intent(in) :: run
    character(len=:), allocatable :: t
    character(len=24) :: buf
    integer(int64) :: n
    integer :: a
    n = 0
    if (allocated(run%systems)) then
      do a = 1, size(run%systems)
        n = n + run%systems(a)%n
      end do
    end if
    write (buf, '(i0)') n
    t = trim(buf)
  end function total_dofs

  !> The contact rows of body a: the rows of every pair it takes part in.
  integer function body_rows(itf, a)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a   !< the body
    integer :: p, s
    body_rows = 0
    if (.not. (allocated(itf%pair_body) .and. allocated(itf%pair_ptr))) return
    do p = 1, itf%npair
      do s = 1, 2
        if (itf%pair_body(s, p) == a) body_rows = body_rows + itf%pair_ptr(p + 1) - itf%pair_ptr(p)
      end do
    end do
  end function body_rows

  !> The `assembled:` line: the DOFs of bodies 1 and 2 (after the supports), the contact
  !! rows of all pairs, the threads, and the totals (bodies, pairs, DOFs); on a deck of more
  !! than two bodies then the `bodies:` line, each body's DOFs and contact rows (the first
  !! MAX_LISTED bodies, then how many more).
  subroutine print_assembled(run)
    type(run_t), intent(in) :: run
    character(len=:), allocatable :: t
    integer :: a
    write (output_unit, '(a)') 'assembled: n1='//i2s(run%systems(1)%n)//' n2='//i2s(run%systems(2)%n)// &
      ' m='//i2s(run%contact_line%m)//' threads='//i2s(run%threads)//' bodies='//i2s(run%nbody)// &
      ' pairs='//i2s(run%contact_line%npair)//' dofs='//total_dofs(run)
    if (run%nbody <= 2) return
    t = 'bodies: dofs,contact_rows'
    do a = 1, min(run%nbody, MAX_LISTED)
      t = t//' '//i2s(a)//'='//i2s(run%systems(a)%n)//','//i2s(body_rows(run%contact_line, a))
    end do
    if (run%nbody > MAX_LISTED) t = t//' ... '//i2s(run%nbody - MAX_LISTED)//' more'
    write (output_unit, '(a)') t
  end subroutine print_assembled

  !> The `contact:` line of each pair: the resultant of its forces on its first body, the sum
  !! of its nodal normal forces, its active rows and imbalance, and the penetration and
  !! complementarity of the whole run (one pair: the line without the pair's name).
  function pair_lines(run) result(lines)
    type(run_t), intent(in) :: run
    character(len=1024), allocatable :: lines(:)
    real(wp) :: ftot, fres(NCOMP), imbalance
    integer :: p, np, r(2), active, nopen
    character(len=:), allocatable :: head, tail
    type(interface_t) :: itf
    type(contact_result_t) :: result
    type(tangential_t) :: tg
    np = max(1, run%contact_line%npair)
    allocate (lines(np))
    ! one entry per contact node: the normal rows, the tangential part beside them
    if (allocated(run%contact_line%dir)) then
      call split_friction(run%contact_line, run%result, itf, result, tg)
    else
      result = run%result
    end if
    do p = 1, np
      ftot = 0.0_wp
      fres = 0.0_wp
      active = result%active
      imbalance = result%imbalance
      head = 'contact: resultant_on_body1='
      tail = ''
      if (allocated(result%lam) .and. itf%npair > 0) then
        r = [itf%pair_ptr(p), itf%pair_ptr(p + 1) - 1]
        ftot = sum(result%lam(r(1):r(2)))
        fres = tg%resultant(:, p)
        if (itf%npair > 1) then
          active = count(result%lam(r(1):r(2)) > 0.0_wp)
          imbalance = 0.0_wp
          if (norm2(result%lam(r(1):r(2))) > 0.0_wp) imbalance = norm2(result%lam_body(r(1):r(2), 1) - &
                                                   result%lam_body(r(1):r(2), 2))/norm2(result%lam(r(1):r(2)))
          head = 'contact: pair='//i2s(p)//' bodies='//i2s(itf%pair_body(1, p))//','//i2s(itf%pair_body(2, p))// &
                 ' resultant_on_body'//i2s(itf%pair_body(1, p))//'='
        end if
        if (tg%on) then
          ! the sum along the tangent in the plane, the vector sum (x, y, z) in space
          if (any(tg%state(r(1):r(2)) >= 0)) tail = ' tangential_force_sum='//tangential_sum(r(1), r(2))// &
            ' stick='//i2s(count(tg%state(r(1):r(2)) == NODE_STICK))//' slip='//i2s(count(tg%state(r(1):r(2)) == NODE_SLIP))
          ! Tresca's bound holds whether or not the surfaces touch: a shear across an open gap
          ! is what given friction means, not a force between bodies that touch; say so
          if (itf%pair_friction(p) == FRICTION_TRESCA) then
            nopen = count(result%lam(r(1):r(2)) <= 0.0_wp .and. any(tg%force(:, r(1):r(2)) /= 0.0_wp, dim=1))
            if (nopen > 0) call warn('pair '//i2s(p)//' (Tresca, slip_bound '//sci(itf%pair_slip(p), 4)// &
              '): '//i2s(nopen)//' of its '//i2s(r(2) - r(1) + 1)//' nodes carry a shear force across an open gap '// &
              '(no normal force; their shear sums to '//open_shear(r(1), r(2))//'): Tresca''s bound acts whether or not the surfaces touch; for a shear that needs '// &
              'contact use friction=''coulomb''')
          end if
        end if
      end if
      write (lines(p), '(a,i0,a,es10.3,a,es10.3,a,es10.3,a)') head// &
        vec_text(fres, ',', 5)//' normal_force_sum='//sci(ftot, 5)//' active=', active, &
        ' imbalance=', imbalance, ' penetration=', result%penetration, ' complementarity=', result%complementarity, tail
    end do

  contains

    !> The tangential forces of rows i..j summed: a number in the plane, a vector in space.
    function tangential_sum(i, j) result(t)
      integer, intent(in) :: i, j
      character(len=:), allocatable :: t
      if (NDIM == 2) then
        t = sci(sum(tg%force(1, i:j)), 5)
      else
        t = vec_text(sum(tg%force_xyz(:, i:j), dim=2), ',', 5)
      end if
    end function tangential_sum

    !> The tangential forces of the rows i..j without a normal force, summed.
    function open_shear(i, j) result(t)
      integer, intent(in) :: i, j
      character(len=:), allocatable :: t
      logical :: open(j - i + 1)
      open = result%lam(i:j) <= 0.0_wp
      if (NDIM == 2) then
        t = sci(sum(pack(tg%force(1, i:j), open)), 4)
      else
        t = vec_text(sum(tg%force_xyz(:, i:j), dim=2, mask=spread(open, 1, NDIM)), ',', 4)
      end if
    end function open_shear

  end function pair_lines

  !> The `reaction:` line of each supported body (the first MAX_LISTED, then how many more):
  !! the resultant of its supports' forces (K u - f at the prescribed DOFs), of its applied
  !! loads and of the contact forces on its free DOFs (-B_a' lam_a), and their balance
  !! |R + F + C| / (the sum of every nodal force's magnitude), with its rounding level (eps
  !! times the size of the terms K u adds up, over the same sum): the body's equilibrium, the
  !! displacement's and the
  !! contact forces' independently (rounding level in a converged run). A contact node on a
  !! support passes its force to the support directly: it is in the pair's resultant, not in
  !! C. None without a displacement (a run that stopped before it), nor for a body whose
  !! interface rows live on another rank.
  function reaction_lines(run) result(lines)
    type(run_t), intent(in) :: run
    character(len=1024), allocatable :: lines(:)
    real(wp), allocatable :: c(:)
    real(wp) :: rr(NCOMP), ff(NCOMP), cc(NCOMP), scale, bal
    integer :: a, p, nsup, k
    allocate (lines(0))
    if (.not. allocated(run%reaction) .or. .not. allocated(run%result%lam_body)) return
    if (.not. allocated(run%bodies)) return
    nsup = 0
    do a = 1, run%nbody
      associate (sy => run%systems(a), cbody => run%bodies(a), r => run%reaction(1:run%systems(a)%ndof, a))
        if (count(sy%free_of == 0) <= sy%nrig) cycle    ! no support: held only by contact (its fixing DOFs)
        if (.not. allocated(cbody%bptr)) cycle
        nsup = nsup + 1
        if (nsup > MAX_LISTED) cycle
        allocate (c(sy%n))
        c = 0.0_wp
        call apply_bt(cbody, gather(run%result%lam_body, cbody%slots), c)
        call to_global(cbody, c)
        cc = 0.0_wp
        do p = 1, sy%n
          cc(dof_comp(sy%dof_of(p))) = cc(dof_comp(sy%dof_of(p))) - c(p)
        end do
        do k = 1, NCOMP
          rr(k) = sum(r(k::NCOMP))
          ff(k) = sum(sy%f_applied(k::NCOMP))
        end do
        ! the size of the forces that balance: every nodal force's magnitude (a body between two
        ! others carries large contact forces whose resultant is zero); K u is known to eps
        ! times the size of its terms, which may cancel far below the forces (a stiff body
        ! moved almost rigidly): that is the rounding level the balance is read against
        scale = max(sum(abs(r)) + sum(abs(sy%f_applied)) + sum(abs(c)), tiny(1.0_wp))
        ! a body of revolution balances along its axis only: the radial forces of a meridian
        ! section are held by its hoop stresses (the x sums are not a resultant)
        if (run%deck%axisymmetric) then
          bal = abs(rr(2) + ff(2) + cc(2))/scale
        else
          bal = norm2(rr + ff + cc)/scale
        end if
        lines = [character(len=1024) :: lines, 'reaction: body='//i2s(a)//' supports='//vec_text(rr, ',', 5)// &
                 ' loads='//vec_text(ff, ',', 5)//' contact='//vec_text(cc, ',', 5)// &
                 ' balance='//sci(bal, 2)//' (rounding '// &
                 sci(epsilon(1.0_wp)*run%reaction_mag(a)/scale, 1)//')'//group_parts(a, r)]
        deallocate (c)
      end associate
    end do
    if (nsup > MAX_LISTED) lines = [character(len=1024) :: lines, 'reaction: ... '//i2s(nsup - MAX_LISTED)// &
                                    ' more supported bodies (the result file has every node''s reaction)']

  contains

    !> ' groups: ''NAME''=Rx,Ry ...': the reaction of each of body a's supports, a rectangle's
    !! clamped, roller or prescribed side and each &boundary group, in that order (the first
    !! 10, then '...'). A DOF counts once, in the first support that prescribes its component
    !! (a clamped corner's uy in the clamp, not in the roller beside it, which holds ux only),
    !! so the groups add up to the body's supports.
    function group_parts(a, r) result(t)
      integer, intent(in) :: a
      real(wp), intent(in) :: r(:)
      character(len=:), allocatable :: t
      type(str_t), allocatable :: names(:)
      logical, allocatable :: comp(:, :), taken(:)
      integer, allocatable :: nodes(:)
      integer :: s, i, g, k, ng, n, c
      real(wp) :: rg(NCOMP)
      allocate (names(0), comp(NCOMP, 0))
      do s = 1, MAX_SIDES
        if (len_trim(run%deck%body(a)%mesh) > 0) exit
        select case (run%deck%body(a)%bc(s))
        case (BC_CLAMPED, BC_DISPLACEMENT)
          names = [names, str_t(trim(side_names(s)))]
          comp = reshape([comp, [(.true., c=1, NCOMP)]], [NCOMP, size(names)])
        case (BC_ROLLER)     ! the normal component: ux on left and right, uy on bottom and top, uz front and back
          names = [names, str_t(trim(side_names(s)))]
          comp = reshape([comp, [(c == side_axis(s), c=1, NCOMP)]], [NCOMP, size(names)])
        end select
      end do
      do i = 1, run%deck%nboundary
        if (run%deck%boundary(i)%body /= a) cycle
        k = findloc([(names(c)%s == trim(run%deck%boundary(i)%group), c=1, size(names))], .true., 1)
        if (k == 0) then
          names = [names, str_t(trim(run%deck%boundary(i)%group))]
          comp = reshape([comp, run%deck%boundary(i)%fix(1:NCOMP)], [NCOMP, size(names)])
        else
          comp(:, k) = comp(:, k) .or. run%deck%boundary(i)%fix(1:NCOMP)
        end if
      end do
      allocate (taken(size(r)))
      taken = .false.
      t = ''
      ng = 0
      do k = 1, size(names)
        g = group_index(run%meshes(a), names(k)%s)
        if (g == 0) cycle
        ng = ng + 1
        if (ng > 10) then
          t = t//' ...'
          exit
        end if
        call group_nodes(run%meshes(a), g, nodes)
        rg = 0.0_wp
        do i = 1, size(nodes)
          do c = 1, NCOMP
            n = node_dof(nodes(i), c)
            if (.not. comp(c, k) .or. taken(n)) cycle
            taken(n) = .true.
            rg(c) = rg(c) + r(n)
          end do
        end do
        t = t//' '''//names(k)%s//'''='//vec_text(rg, ',', 5)
      end do
      if (ng > 0) t = ' groups:'//t
    end function group_parts

  end function reaction_lines

  !> What a user whose Robin run did not converge should try next, in order: the robust
  !! operator and relaxation (the defaults), then the monolithic reference.
  function next_setting(solver, monolithic) result(t)
    type(solver_cfg_t), intent(in) :: solver
    logical, intent(in) :: monolithic   !< the contact problem was solved as one QP (method monolithic)
    character(len=:), allocatable :: t
    if (monolithic) then   ! the Robin settings say nothing of it, and it is already the monolithic QP
      t = "try a looser tolerance, &solver monolithic_rtol="//sci(min(100.0_wp*solver%monolithic_rtol, 1.0e-2_wp), 1)// &
          " / (now "//sci(solver%monolithic_rtol, 1)//"), or a larger inner_max_it (now "//i2s(solver%inner_max_it)// &
          "); and check that the scene is in equilibrium (supports, loads, a body held only by contact)"
    else if (solver%robin_operator /= ROBIN_HARMONIC) then
      t = "try &solver robin_operator='harmonic', delta=0.5 / (robust to material contrast), "// &
          "or method='monolithic'"
    else if (abs(solver%delta - 0.5_wp) > 0.01_wp) then
      t = "try &solver delta=0.5 / (the harmonic operator's best relaxation), or method='monolithic'"
    else
      t = "try &solver method='monolithic' / (one QP over all bodies, no outer iteration), "// &
          "or a larger max_outer"
    end if
  end function next_setting

  !> A vector's components as text, sci with `digits` significant digits, joined by `sep`.
  function vec_text(v, sep, digits) result(t)
    real(wp), intent(in) :: v(:)
    character(len=*), intent(in) :: sep
    integer, intent(in) :: digits
    character(len=:), allocatable :: t
    integer :: k
    t = sci(v(1), digits)
    do k = 2, size(v)
      t = t//sep//sci(v(k), digits)
    end do
  end function vec_text

end module run_summary
