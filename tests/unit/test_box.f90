!> Unit tests of the box meshes (mesh::box_build): node and cell counts, every cell positively
!! oriented, the six side groups outward and tiling their sides, the tetrahedra conforming (every
!! triangle of the split a face of two tetrahedra, or of one on the boundary, where it is a face
!! of a side group and the group names that tetrahedron).
program test_box
  use kinds, only: wp
  use space, only: set_dimension
  use config, only: body_cfg_t, ELEM_Q1, ELEM_P1, ELEM_HEX8, ELEM_TET4, MAX_SIDES, UNSET, side_axis
  use mesh, only: mesh_t
  use elements_3d, only: face_area_normal, tet4_gradients, hex8_gradients
  use testing, only: box_mesh_parts, report, report_le, test_summary
  implicit none (type, external)

  call set_dimension(3)
  call test_box_of(ELEM_Q1, 'hexahedra')
  call test_box_of(ELEM_P1, 'tetrahedra')
  call test_bad_grid()
  call test_summary()

contains

  subroutine test_box_of(element, what)
    integer, intent(in) :: element
    character(len=*), intent(in) :: what
    type(body_cfg_t) :: b
    type(mesh_t) :: m
    integer :: info, c, s, f, nv, a, k, nneg, nbad, i, j, t, nonce, nb
    character(len=256) :: msg
    real(wp) :: xe(3, 8), g(3, 8), nfun(8), det, xf(3, 4), an(3), area(MAX_SIDES), e_area, vol, outward(3)
    real(wp), parameter :: ext(3) = [2.0_wp, 1.5_wp, 0.75_wp], org(3) = [-1.0_wp, 0.5_wp, 3.0_wp]
    integer, allocatable :: faces(:, :), cnt(:)
    logical :: found

    b%id = 1
    b%x0 = org(1)
    b%y0 = org(2)
    b%z0 = org(3)
    b%width = ext(1)
    b%height = ext(2)
    b%depth = ext(3)
    b%nx = 4
    b%ny = 3
    b%nz = 2
    b%element = element
    call box_mesh_parts(m, b, info, msg)
    call report(info == 0, what//': built ('//trim(msg)//')')
    if (info /= 0) return
    call report(m%nnode == 5*4*3 .and. m%ncell == 4*3*2*merge(1, 6, element == ELEM_Q1) .and. &
                m%element == merge(ELEM_HEX8, ELEM_TET4, element == ELEM_Q1) .and. m%box .and. .not. m%structured, &
                what//': node and cell counts, element, a box')
    ! every cell positive; the volumes sum to the box's
    nneg = 0
    vol = 0.0_wp
    nv = size(m%cells, 1)
    do c = 1, m%ncell
      xe = 0.0_wp
      do a = 1, nv
        xe(:, a) = m%xy(:, m%cells(a, c))
      end do
      if (nv == 8) then
        call hex8_gradients(xe, 0.0_wp, 0.0_wp, 0.0_wp, nfun, g, det)
        vol = vol + 8.0_wp*det                   ! a grid cell: constant Jacobian
      else
        call tet4_gradients(xe(:, 1:4), g(:, 1:4), det)
        vol = vol + det/6.0_wp
      end if
      if (.not. det > 0.0_wp) nneg = nneg + 1
    end do
    call report(nneg == 0, what//': every cell positively oriented')
    call report_le(abs(vol - product(ext))/product(ext), 1.0e-13_wp, what//': the cells'' volumes sum to the box''s')
    ! the sides: outward, tiling their rectangles
    nbad = 0
    area = 0.0_wp
    do s = 1, MAX_SIDES
      outward = 0.0_wp
      outward(side_axis(s)) = merge(-1.0_wp, 1.0_wp, mod(s, 2) == 1)
      do f = 1, m%group(s)%nedge
        k = count(m%group(s)%edge(:, f) > 0)
        xf = 0.0_wp
        do a = 1, k
          xf(:, a) = m%xy(:, m%group(s)%edge(a, f))
          if (abs(xf((s + 1)/2, a) - (org((s + 1)/2) + merge(0.0_wp, ext((s + 1)/2), mod(s, 2) == 1))) > 1.0e-12_wp) &
            nbad = nbad + 1
        end do
        call face_area_normal(k, xf, an)
        if (.not. dot_product(an, outward) > 0.0_wp) nbad = nbad + 1
        area(s) = area(s) + norm2(an)
        ! the face belongs to the cell the group names
        do a = 1, k
          if (.not. any(m%cells(:, m%group(s)%cell(f)) == m%group(s)%edge(a, f))) nbad = nbad + 1
        end do
      end do
    end do
    call report(nbad == 0, what//': each side''s faces on it, outward, faces of the cells named')
    e_area = 0.0_wp
    do s = 1, MAX_SIDES
      i = merge(2, 1, (s + 1)/2 == 1)
      j = merge(2, 3, (s + 1)/2 == 3)
      if ((s + 1)/2 == 2) then
        i = 1
        j = 3
      end if
      e_area = max(e_area, abs(area(s) - ext(i)*ext(j))/(ext(i)*ext(j)))
    end do
    call report_le(e_area, 1.0e-13_wp, what//': each side''s faces tile it (areas)')
    if (nv /= 4) return
    ! conformity: every triangle of every tetrahedron is a face of two, or of one and then of a side
    allocate (faces(3, 4*m%ncell), cnt(4*m%ncell))
    k = 0
    do t = 1, m%ncell
      do a = 1, 4
        k = k + 1
        faces(:, k) = sorted3(pack(m%cells(:, t), [(i /= a, i=1, 4)]))
      end do
    end do
    cnt = 0
    do i = 1, k
      cnt(i) = count(faces(1, :) == faces(1, i) .and. faces(2, :) == faces(2, i) .and. faces(3, :) == faces(3, i))
    end do
    nonce = count(cnt == 1)
    nb = sum([(m%group(s)%nedge, s=1, MAX_SIDES)])
    call report(all(cnt == 1 .or. cnt == 2) .and. nonce == nb, what//': conforming (every triangle in two '// &
                'tetrahedra, or in one on the boundary)')
    nbad = 0
    do s = 1, MAX_SIDES
      do f = 1, m%group(s)%nedge
        found = .false.
        do i = 1, k
          if (cnt(i) == 1 .and. all(faces(:, i) == sorted3(m%group(s)%edge(1:3, f)))) found = .true.
        end do
        if (.not. found) nbad = nbad + 1
      end do
    end do
    call report(nbad == 0, what//': every side triangle is a boundary face of the split')
  end subroutine test_box_of

  !> A bad grid or extent is refused with a sentence naming the body.
  subroutine test_bad_grid()
    type(body_cfg_t) :: b
    type(mesh_t) :: m
    integer :: info
    character(len=256) :: msg
    b%id = 7
    b%depth = 1.0_wp
    b%nz = 0
    call box_mesh_parts(m, b, info, msg)
    call report(info /= 0 .and. index(msg, 'body 7') > 0 .and. index(msg, 'nz') > 0, 'nz = 0 refused ('//trim(msg)//')')
    b%nz = 2
    b%depth = UNSET
    call box_mesh_parts(m, b, info, msg)
    call report(info /= 0 .and. index(msg, 'depth') > 0, 'depth not positive refused ('//trim(msg)//')')
  end subroutine test_bad_grid

  pure function sorted3(v) result(w)
    integer, intent(in) :: v(3)
    integer :: w(3)
    w = [minval(v), sum(v) - minval(v) - maxval(v), maxval(v)]
  end function sorted3

end program test_box
