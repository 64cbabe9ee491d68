!> One body's mesh from a Gmsh MSH 4.1 ASCII file: the triangles and quadrangles of a
!! physical surface, their nodes, and the boundary edges of every physical curve as named
!! edge groups (module mesh, type mesh_t).
!!
!! The file is read whole into memory and scanned once, token by token, with hand-written
!! integer and real conversions: a list-directed READ costs about 1.7 us a number, several
!! seconds for the 4 million numbers of a 500k-node mesh, which this reads in about 1 s
!! (peak memory about 2.8 times the file). Node tags are looked up through a hash table, so
!! tags may be sparse and unordered; the body's nodes are renumbered 1..nnode in increasing
!! tag order. Cells are reoriented counter-clockwise; degenerate cells and non-convex
!! quadrangles are refused.
!! A group keeps the line elements of its physical curve that are boundary edges of the body
!! (edges of exactly one body cell), oriented as that cell traverses them; the nodes of its
!! lines inside the body (edges of two body cells) are kept as single nodes. A physical point
!! (point elements, type 15) is a group of single nodes: those of its points that are nodes
!! of the body. Gmsh gives a point that bounds or is embedded in a meshed surface the node of
!! the surface's mesh; a point's node in no cell of the file (a free geometry point) is the
!! body's node at the same place, within 1e-9 times the body's size, if it has one.
!!
!! Errors: info = 1 for bad input (msg names the file and the line or element tag), 3 for
!! other failures (memory). Only first-order elements (2-node lines, 3-node triangles,
!! 4-node quadrangles, points) in the plane z = 0 are read.
module gmsh_msh
  use kinds, only: wp, i8
  use config, only: ELEM_Q1, ELEM_P1, ELEM_MIXED
  use strings, only: i2s, fpstate_t, fp_read_begin, fp_read_end
  use mesh, only: mesh_t
  implicit none (type, external)
  private


  public :: msh_read, msh_read_pair

  integer, parameter :: BAD_INPUT = 1, OTHER_FAILURE = 3
  integer(i8), parameter :: EMPTY = -1_i8            ! an unused hash slot
  real(wp), parameter :: AREA_TOL = 1.0e-12_wp       ! degenerate: |area| < AREA_TOL * (longest edge)^2
  real(wp), parameter :: p10(0:22) = [ &   ! the powers of ten that doubles hold exactly
    1.0e0_wp, 1.0e1_wp, 1.0e2_wp, 1.0e3_wp, 1.0e4_wp, 1.0e5_wp, 1.0e6_wp, 1.0e7_wp, 1.0e8_wp, &
    1.0e9_wp, 1.0e10_wp, 1.0e11_wp, 1.0e12_wp, 1.0e13_wp, 1.0e14_wp, 1.0e15_wp, 1.0e16_wp, &
    1.0e17_wp, 1.0e18_wp, 1.0e19_wp, 1.0e20_wp, 1.0e21_wp, 1.0e22_wp]

  !> The file's text and a reading position, with the first error met.
  type :: cursor_t
    character(len=:), allocatable :: text   ! the whole file
    integer(i8) :: n = 0                    ! its length
    integer(i8) :: pos = 1                  ! next character
    integer :: line = 1                     ! the line of pos
    character(len=:), allocatable :: path     ! the file
    character(len=:), allocatable :: section  ! the section being read, for messages
    integer :: info = 0                     ! first error: code
    integer :: err_line = 0                 ! its line (0: none)
    character(len=:), allocatable :: err    ! its text
  end type cursor_t

  !> Open-addressing hash set of non-negative 64-bit keys; slot data are kept by the caller.
  type :: hash_t
    integer(i8), allocatable :: key(:)
    integer(i8) :: mask = 0
  end type hash_t

  type :: name_t
    character(len=:), allocatable :: s
  end type name_t

  !> A point, curve or surface entity and its physical tags.
  type :: entity_t
    integer :: dim = 0, tag = 0
    integer, allocatable :: phys(:)
  end type entity_t

  !> What the file holds, before a body is chosen.
  type :: msh_data_t
    integer :: nphys = 0                       ! physical groups (named or not)
    integer, allocatable :: pdim(:), ptag(:)
    type(name_t), allocatable :: pname(:)
    integer :: nent = 0                        ! point, curve and surface entities
    type(entity_t), allocatable :: ent(:)
    integer :: nnode = 0                       ! nodes, in file order
    integer, allocatable :: ntag(:)
    real(wp), allocatable :: nxy(:, :)
    type(hash_t) :: node_hash                  ! node tag -> slot; slot_node(slot) = file index
    integer, allocatable :: slot_node(:)
    integer :: ncell = 0                       ! triangles and quadrangles, file order
    integer, allocatable :: ctag(:), cent(:), cnode(:, :)   ! tag, entity index (0: none), 4 file indices (0)
    integer :: nline = 0                       ! 2-node lines
    integer, allocatable :: lent(:), lnode(:, :)              ! entity index, 2 file indices
    integer :: npoint = 0                      ! point elements
    integer, allocatable :: pent(:), pnode(:)                 ! entity index, file index
    logical :: has_format = .false., has_nodes = .false., has_elements = .false.
  end type msh_data_t

contains

  !> Read one body of a Gmsh MSH 4.1 ASCII file into `mesh`.
  !!
  !! The body is the triangles and quadrangles of the physical surface named `region`; with
  !! region = '' the file may hold at most one physical surface, and a file without physical
  !! groups gives every 2D element. `mesh` gets the body's nodes (renumbered by increasing
  !! Gmsh tag, `node_tag` keeps the tag), its cells counter-clockwise (`cell_tag`,
  !! `cell_type`), element = ELEM_Q1, ELEM_P1 or ELEM_MIXED, the bounding box, one edge
  !! group per physical curve with edges on the body's boundary, then one node group per
  !! physical point with nodes of the body (`file_groups` lists every physical curve and
  !! point name of the file).
  subroutine msh_read(path, region, body_id, mesh, info, msg)
    character(len=*), intent(in) :: path     !< the .msh file
    character(len=*), intent(in) :: region   !< physical surface name of the body, or ''
    integer, intent(in) :: body_id           !< the body's number, for messages
    type(mesh_t), intent(out) :: mesh        !< the body's mesh
    integer, intent(out) :: info             !< 0; 1 bad input; 3 other failure
    character(len=*), intent(out) :: msg     !< one sentence when info /= 0
    type(cursor_t) :: cur
    type(msh_data_t) :: d

    cur%path = path
    cur%section = ''
    allocate (d%pdim(8), d%ptag(8), d%pname(8))
    call load_file(path, cur)
    if (cur%info == 0) call parse(cur, d)
    if (cur%info == 0) call build_body(cur, d, trim(region), mesh)
    if (allocated(cur%text)) deallocate (cur%text)
    call outcome(cur, path, body_id, mesh, info, msg)
  end subroutine msh_read

  !> Both bodies from one .msh file (the same path for both): the file is read and parsed
  !! once, then each body is built from it (the bodies in parallel on two threads when
  !! `nthr` is 2). Arguments as msh_read's, one per body.
  subroutine msh_read_pair(path, region, mesh, info, msg, nthr)
    character(len=*), intent(in) :: path          !< the .msh file of both bodies
    character(len=*), intent(in) :: region(2)     !< physical surface name of each body
    type(mesh_t), intent(out) :: mesh(2)          !< the bodies' meshes
    integer, intent(out) :: info(2)               !< 0; 1 bad input; 3 other failure
    character(len=*), intent(out) :: msg(2)       !< one sentence when info /= 0
    integer, intent(in) :: nthr                   !< threads for the two builds (1 or 2)
    type(cursor_t) :: cur, cb(2)
    type(msh_data_t) :: d
    integer :: a

    cur%path = path
    cur%section = ''
    allocate (d%pdim(8), d%ptag(8), d%pname(8))
    call load_file(path, cur)
    if (cur%info == 0) call parse(cur, d)
    if (allocated(cur%text)) deallocate (cur%text)
    do a = 1, 2
      cb(a) = cur
    end do
    !$omp parallel do num_threads(nthr) schedule(static, 1)
    do a = 1, 2
      if (cb(a)%info == 0) call build_body(cb(a), d, trim(region(a)), mesh(a))
    end do
    !$omp end parallel do
    do a = 1, 2
      call outcome(cb(a), path, a, mesh(a), info(a), msg(a))
    end do
  end subroutine msh_read_pair

  !> The status of a read: info from the cursor and, on failure, one sentence naming the body,
  !! the file and the line, and an empty mesh.
  subroutine outcome(cur, path, body_id, mesh, info, msg)
    type(cursor_t), intent(in) :: cur
    character(len=*), intent(in) :: path
    integer, intent(in) :: body_id
    type(mesh_t), intent(inout) :: mesh
    integer, intent(out) :: info
    character(len=*), intent(out) :: msg
    info = cur%info
    msg = ''
    if (info == 0) return
    msg = 'body '//i2s(body_id)//": mesh file '"//trim(path)//"'"
    if (cur%err_line > 0) msg = trim(msg)//', line '//i2s(cur%err_line)
    msg = trim(msg)//': '//cur%err//'.'
    mesh%nnode = 0
    mesh%ncell = 0
  end subroutine outcome

  ! ---- errors ---------------------------------------------------------------------------

  !> Record an error (the first one only) at the current line, or with no line (at_line false).
  subroutine fail(cur, text, code, at_line)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: text
    integer, intent(in), optional :: code
    logical, intent(in), optional :: at_line
    if (cur%info /= 0) return
    cur%info = BAD_INPUT
    if (present(code)) cur%info = code
    cur%err_line = cur%line
    if (present(at_line)) then
      if (.not. at_line) cur%err_line = 0
    end if
    cur%err = text
  end subroutine fail

  ! ---- the text -------------------------------------------------------------------------

  !> Read the whole file into cur%text.
  subroutine load_file(path, cur)
    character(len=*), intent(in) :: path
    type(cursor_t), intent(inout) :: cur
    integer :: u, ios, st
    integer(i8) :: size_bytes
    character(len=256) :: iom

    open (newunit=u, file=path, access='stream', form='unformatted', status='old', &
          action='read', iostat=ios, iomsg=iom)
    if (ios /= 0) then
      call fail(cur, 'cannot be opened ('//trim(iom)//')', at_line=.false.)
      return
    end if
    inquire (unit=u, size=size_bytes)
    if (size_bytes <= 0) then
      close (u)
      call fail(cur, 'is empty or not a regular file', at_line=.false.)
      return
    end if
    allocate (character(len=size_bytes) :: cur%text, stat=st)
    if (st /= 0) then
      close (u)
      call fail(cur, 'needs '//i2s(int(size_bytes/2**20))//' MB of memory to be read', &
                OTHER_FAILURE, .false.)
      return
    end if
    read (u, iostat=ios, iomsg=iom) cur%text
    close (u)
    if (ios /= 0) then
      call fail(cur, 'cannot be read ('//trim(iom)//')', at_line=.false.)
      return
    end if
    cur%n = size_bytes
  end subroutine load_file

  !> The next token (characters above the blank) as text(s:e); s > cur%n at the end of the
  !! file. Blanks, tabs, carriage returns and other control characters separate tokens.
  subroutine next_token(cur, s, e)
    type(cursor_t), intent(inout) :: cur
    integer(i8), intent(out) :: s, e
    integer :: code
    do while (cur%pos <= cur%n)
      code = iachar(cur%text(cur%pos:cur%pos))
      if (code > 32) exit
      if (code == 10) cur%line = cur%line + 1
      cur%pos = cur%pos + 1
    end do
    s = cur%pos
    do while (cur%pos <= cur%n)
      if (iachar(cur%text(cur%pos:cur%pos)) <= 32) exit
      cur%pos = cur%pos + 1
    end do
    e = cur%pos - 1
  end subroutine next_token

  !> Report the end of the file inside a section, or a token that is not `what`.
  subroutine bad_token(cur, s, e, what)
    type(cursor_t), intent(inout) :: cur
    integer(i8), intent(in) :: s, e
    character(len=*), intent(in) :: what
    if (s > cur%n) then
      call fail(cur, 'the file ends inside '//cur%section//' where '//what// &
                ' was expected (truncated file?)')
    else
      call fail(cur, 'expected '//what//' in '//cur%section//", found '"// &
                cur%text(s:min(e, s + 40))//"'")
    end if
  end subroutine bad_token

  !> The next token as an integer (0 after an error).
  integer function get_int(cur, what) result(v)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: what   ! what the number is, for messages
    integer(i8) :: s, e
    logical :: ok
    v = 0
    if (cur%info /= 0) return
    call next_token(cur, s, e)
    ok = s <= e
    if (ok) call parse_int(cur%text(s:e), v, ok)
    if (.not. ok) call bad_token(cur, s, e, what//' (an integer)')
  end function get_int

  !> The next token as a real (0 after an error).
  real(wp) function get_real(cur, what) result(v)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: what
    integer(i8) :: s, e
    logical :: ok
    v = 0.0_wp
    if (cur%info /= 0) return
    call next_token(cur, s, e)
    ok = s <= e
    if (ok) call parse_real(cur%text(s:e), v, ok)
    if (.not. ok) call bad_token(cur, s, e, what//' (a finite real)')
  end function get_real

  !> The next token must be `word` (a section's end marker).
  subroutine expect(cur, word)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: word
    integer(i8) :: s, e
    if (cur%info /= 0) return
    call next_token(cur, s, e)
    if (s > cur%n) then
      call fail(cur, 'the file ends before '//word//' (truncated file?)')
    else if (cur%text(s:e) /= word) then
      call fail(cur, 'expected '//word//" to close "//cur%section//", found '"// &
                cur%text(s:min(e, s + 40))//"'")
    end if
  end subroutine expect

  !> Skip an unknown section up to its end marker.
  subroutine skip_section(cur, name)
    type(cursor_t), intent(inout) :: cur
    character(len=*), intent(in) :: name   ! without the '$'
    integer(i8) :: k, stop_at
    k = index(cur%text(cur%pos:cur%n), '$End'//name, kind=i8)
    if (k == 0) then
      call fail(cur, 'the file ends before $End'//name//' (truncated file?)')
      return
    end if
    stop_at = cur%pos + k - 1
    do while (cur%pos < stop_at)
      if (cur%text(cur%pos:cur%pos) == achar(10)) cur%line = cur%line + 1
      cur%pos = cur%pos + 1
    end do
    cur%pos = stop_at + 4 + len(name)
  end subroutine skip_section

  !> A decimal integer with an optional sign, in the default integer range.
  pure subroutine parse_int(t, v, ok)
    character(len=*), intent(in) :: t
    integer, intent(out) :: v
    logical, intent(out) :: ok
    integer :: i, i0, d
    integer(i8) :: m
    v = 0
    i0 = 1
    if (t(1:1) == '-' .or. t(1:1) == '+') i0 = 2
    ok = len(t) >= i0 .and. len(t) - i0 < 18
    if (.not. ok) return
    m = 0
    do i = i0, len(t)
      d = iachar(t(i:i)) - iachar('0')
      if (d < 0 .or. d > 9) then
        ok = .false.
        return
      end if
      m = 10*m + d
    end do
    if (t(1:1) == '-') m = -m
    ok = abs(m) <= huge(v)
    if (ok) v = int(m)
  end subroutine parse_int

  !> A decimal real. Exact (correctly rounded) in the common case of at most 18 significant
  !! digits with a mantissa below 2**53 and a power of ten up to 22 (one multiplication or
  !! division of two exact doubles); other forms go through a formatted READ.
  subroutine parse_real(t, v, ok)
    character(len=*), intent(in) :: t
    real(wp), intent(out) :: v
    logical, intent(out) :: ok
    integer :: i, d, nsig, e10, ex, esign
    integer(i8) :: m
    logical :: digits, neg
    type(fpstate_t) :: fp
    integer :: ios

    v = 0.0_wp
    i = 1
    neg = t(1:1) == '-'
    if (t(1:1) == '-' .or. t(1:1) == '+') i = 2
    m = 0
    nsig = 0
    e10 = 0
    digits = .false.
    ok = .true.
    do while (i <= len(t))                       ! integer part
      d = iachar(t(i:i)) - iachar('0')
      if (d < 0 .or. d > 9) exit
      digits = .true.
      if (nsig >= 18) then
        ok = .false.
      else
        m = 10*m + d
        if (m > 0) nsig = nsig + 1
      end if
      i = i + 1
    end do
    if (i <= len(t)) then                        ! fraction
      if (t(i:i) == '.') then
        i = i + 1
        do while (i <= len(t))
          d = iachar(t(i:i)) - iachar('0')
          if (d < 0 .or. d > 9) exit
          digits = .true.
          if (nsig >= 18) then
            ok = .false.
          else
            m = 10*m + d
            if (m > 0) nsig = nsig + 1
            e10 = e10 - 1
          end if
          i = i + 1
        end do
      end if
    end if
    if (i <= len(t)) then                        ! exponent
      if (t(i:i) == 'e' .or. t(i:i) == 'E') then
        i = i + 1
        esign = 1
        if (i <= len(t)) then
          if (t(i:i) == '-') esign = -1
          if (t(i:i) == '-' .or. t(i:i) == '+') i = i + 1
        end if
        ex = 0
        digits = digits .and. i <= len(t)
        do while (i <= len(t))
          d = iachar(t(i:i)) - iachar('0')
          if (d < 0 .or. d > 9) exit
          if (ex < 100000) ex = 10*ex + d
          i = i + 1
        end do
        e10 = e10 + esign*ex
      end if
    end if
    ok = ok .and. digits .and. i > len(t)
    if (ok .and. m == 0) then
      v = 0.0_wp
    else if (ok .and. m <= 2_i8**53 .and. abs(e10) <= 22) then
      v = real(m, wp)
      if (e10 >= 0) then
        v = v*p10(e10)
      else
        v = v/p10(-e10)
      end if
    else
      ! Rare forms (17+ digits, large exponents, 'D' exponents): a formatted READ, only of
      ! number characters (a list-directed READ would take '/' or ',' as separators).
      ok = len(t) <= 64 .and. verify(t, '0123456789+-.eEdD') == 0
      if (.not. ok) return
      call fp_read_begin(fp)
      read (t, '(f64.0)', iostat=ios) v
      call fp_read_end(fp)
      ok = ios == 0 .and. abs(v) <= huge(v)
      return
    end if
    if (neg) v = -v
  end subroutine parse_real

  ! ---- hash set ---------------------------------------------------------------------------

  subroutine hash_init(h, n, stat)
    type(hash_t), intent(out) :: h
    integer, intent(in) :: n        ! keys to hold
    integer, intent(out) :: stat
    integer(i8) :: cap
    cap = 16
    do while (cap < 2_i8*n)
      cap = 2*cap
    end do
    allocate (h%key(0:cap - 1), stat=stat)
    if (stat /= 0) return
    h%key = EMPTY
    h%mask = cap - 1
  end subroutine hash_init

  !> The slot (0-based) holding `key`, or the empty slot where it goes (linear probing; the
  !! table is at most half full). The key's two 32-bit halves are folded and scrambled by a
  !! 32-bit multiplicative mix whose products stay below 2**63 (no integer overflow).
  pure integer function hash_slot(h, key) result(slot)
    type(hash_t), intent(in) :: h
    integer(i8), intent(in) :: key
    integer(i8), parameter :: low32 = 2_i8**32 - 1, mult = 73244475_i8
    integer(i8) :: k
    k = ieor(iand(key, low32), ishft(key, -32))
    k = iand(ieor(k, ishft(k, -16))*mult, low32)
    k = iand(ieor(k, ishft(k, -16))*mult, low32)
    k = ieor(k, ishft(k, -16))
    k = iand(k, h%mask)
    do while (h%key(k) /= EMPTY .and. h%key(k) /= key)
      k = iand(k + 1, h%mask)
    end do
    slot = int(k)
  end function hash_slot

  ! ---- parsing ----------------------------------------------------------------------------

  !> Read every section of the file into d.
  subroutine parse(cur, d)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(inout) :: d
    integer(i8) :: s, e
    character(len=:), allocatable :: tok

    do
      call next_token(cur, s, e)
      if (s > cur%n) exit
      tok = cur%text(s:e)
      if (.not. d%has_format .and. tok /= '$MeshFormat') then
        call fail(cur, "does not start with $MeshFormat (found '"//tok(1:min(len(tok), 40))// &
                  "'): not a Gmsh MSH file")
        return
      end if
      cur%section = tok
      if ((tok == '$Entities' .and. allocated(d%ent)) .or. (tok == '$Nodes' .and. d%has_nodes) .or. &
          (tok == '$Elements' .and. d%has_elements) .or. (tok == '$MeshFormat' .and. d%has_format)) then
        call fail(cur, 'has a second '//tok//' section')
        return
      end if
      select case (tok)
      case ('$MeshFormat')
        call read_format(cur)
        d%has_format = .true.
      case ('$PhysicalNames')
        call read_physical_names(cur, d)
      case ('$Entities')
        call read_entities(cur, d)
      case ('$Nodes')
        call read_nodes(cur, d)
        d%has_nodes = .true.
      case ('$Elements')
        if (.not. d%has_nodes) call fail(cur, '$Elements comes before $Nodes')
        call read_elements(cur, d)
        d%has_elements = .true.
      case default
        if (tok(1:1) /= '$' .or. len(tok) < 2) then
          call fail(cur, "expected a section such as $Nodes, found '"//tok(1:min(len(tok), 40))//"'")
        else if (index(tok, '$End') == 1) then
          call fail(cur, tok//' without its section')
        else
          call skip_section(cur, tok(2:))
        end if
      end select
      if (cur%info /= 0) return
    end do
    if (.not. d%has_format) then
      call fail(cur, 'is empty: no $MeshFormat section')
    else if (.not. d%has_nodes) then
      call fail(cur, 'has no $Nodes section (truncated file?)')
    else if (.not. d%has_elements) then
      call fail(cur, 'has no $Elements section (truncated file?)')
    end if
  end subroutine parse

  !> $MeshFormat: version 4.1, ASCII.
  subroutine read_format(cur)
    type(cursor_t), intent(inout) :: cur
    integer(i8) :: s, e
    integer :: file_type, data_size
    call next_token(cur, s, e)
    if (s > cur%n) then
      call fail(cur, 'the file ends inside $MeshFormat (truncated file?)')
      return
    end if
    if (cur%text(s:e) /= '4.1') then
      call fail(cur, 'is MSH version '//cur%text(s:min(e, s + 20))//', and only MSH 4.1 is read; '// &
                'write version 4.1 with `gmsh -format msh41` or Mesh.MshFileVersion = 4.1')
      return
    end if
    file_type = get_int(cur, 'the file type')
    if (cur%info == 0 .and. file_type /= 0) then
      call fail(cur, 'is a binary MSH file, and only ASCII is read; write it without -bin '// &
                '(Mesh.Binary = 0)')
      return
    end if
    data_size = get_int(cur, 'the data size')
    call expect(cur, '$EndMeshFormat')
  end subroutine read_format

  !> $PhysicalNames: dimension, tag and quoted name of each physical group.
  subroutine read_physical_names(cur, d)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(inout) :: d
    integer :: n, k, dim, tag
    integer(i8) :: q
    n = get_int(cur, 'the number of physical names')
    if (cur%info /= 0) return
    do k = 1, n
      dim = get_int(cur, 'a physical dimension')
      tag = get_int(cur, 'a physical tag')
      if (cur%info /= 0) return
      ! the name: from the opening quote to the closing one on the same line
      do while (cur%pos <= cur%n)
        if (cur%text(cur%pos:cur%pos) /= ' ' .and. cur%text(cur%pos:cur%pos) /= achar(9)) exit
        cur%pos = cur%pos + 1
      end do
      if (cur%pos > cur%n) then
        call fail(cur, 'the file ends inside $PhysicalNames (truncated file?)')
        return
      end if
      q = 0
      if (cur%text(cur%pos:cur%pos) == '"') q = scan(cur%text(cur%pos + 1:min(cur%n, cur%pos + 1024)), '"'//achar(10))
      if (q == 0) then
        call fail(cur, 'a physical name must be in double quotes on one line')
        return
      end if
      if (cur%text(cur%pos + q:cur%pos + q) /= '"') then
        call fail(cur, 'a physical name must be in double quotes on one line')
        return
      end if
      call add_physical(d, dim, tag, cur%text(cur%pos + 1:cur%pos + q - 1))
      cur%pos = cur%pos + q + 1
    end do
    call expect(cur, '$EndPhysicalNames')
  end subroutine read_physical_names

  !> Add a physical group (dim, tag) named `name` unless it is there already.
  subroutine add_physical(d, dim, tag, name)
    type(msh_data_t), intent(inout) :: d
    integer, intent(in) :: dim, tag
    character(len=*), intent(in) :: name
    integer, allocatable :: idim(:), itag(:)
    type(name_t), allocatable :: nm(:)
    integer :: k
    do k = 1, d%nphys
      if (d%pdim(k) == dim .and. d%ptag(k) == tag) return
    end do
    if (d%nphys == size(d%pdim)) then
      allocate (idim(2*d%nphys), itag(2*d%nphys), nm(2*d%nphys))
      idim(1:d%nphys) = d%pdim
      itag(1:d%nphys) = d%ptag
      do k = 1, d%nphys
        call move_alloc(d%pname(k)%s, nm(k)%s)
      end do
      call move_alloc(idim, d%pdim)
      call move_alloc(itag, d%ptag)
      call move_alloc(nm, d%pname)
    end if
    d%nphys = d%nphys + 1
    d%pdim(d%nphys) = dim
    d%ptag(d%nphys) = tag
    d%pname(d%nphys)%s = name
  end subroutine add_physical

  !> $Entities: the physical tags of every point, curve and surface (volumes skipped).
  subroutine read_entities(cur, d)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(inout) :: d
    integer :: nents(0:3), dim, k, j, nb, tag, np, bound
    real(wp) :: r
    integer, allocatable :: phys(:)
    do dim = 0, 3
      nents(dim) = get_int(cur, 'the number of entities')
    end do
    if (cur%info /= 0) return
    if (any(nents < 0)) then
      call fail(cur, 'negative numbers of entities')
      return
    end if
    allocate (d%ent(nents(0) + nents(1) + nents(2)))
    do dim = 0, 3
      do k = 1, nents(dim)
        tag = get_int(cur, 'an entity tag')
        do j = 1, merge(3, 6, dim == 0)
          r = get_real(cur, 'an entity coordinate')
        end do
        np = get_int(cur, 'the number of physical tags')
        if (cur%info /= 0) return
        if (np < 0) then
          call fail(cur, 'a negative number of physical tags')
          return
        end if
        allocate (phys(np))
        do j = 1, np     ! negative when the entity is reversed in the group
          phys(j) = abs(get_int(cur, 'a physical tag'))
        end do
        if (dim > 0) then
          nb = get_int(cur, 'the number of bounding entities')
          do j = 1, nb
            bound = get_int(cur, 'a bounding entity tag')
          end do
        end if
        if (cur%info /= 0) return
        if (dim <= 2) then
          d%nent = d%nent + 1
          d%ent(d%nent)%dim = dim
          d%ent(d%nent)%tag = tag
          call move_alloc(phys, d%ent(d%nent)%phys)
          do j = 1, np        ! physical groups without a name are named by their tag
            call add_physical(d, dim, d%ent(d%nent)%phys(j), i2s(d%ent(d%nent)%phys(j)))
          end do
        else
          deallocate (phys)
        end if
      end do
    end do
    call expect(cur, '$EndEntities')
  end subroutine read_entities

  !> $Nodes: blocks of tags then coordinates; z must be 0.
  subroutine read_nodes(cur, d)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(inout) :: d
    integer :: nblock, ntotal, b, edim, etag, param, nb, k, j, st, slot, first
    real(wp) :: z, r

    nblock = get_int(cur, 'the number of node blocks')
    ntotal = get_int(cur, 'the number of nodes')
    k = get_int(cur, 'the smallest node tag')
    k = get_int(cur, 'the largest node tag')
    if (cur%info /= 0) return
    if (nblock < 0 .or. ntotal < 0) then
      call fail(cur, 'negative numbers of node blocks or nodes')
      return
    end if
    allocate (d%ntag(ntotal), d%nxy(2, ntotal), stat=st)
    if (st == 0) call hash_init(d%node_hash, ntotal, st)
    if (st == 0) allocate (d%slot_node(0:d%node_hash%mask), stat=st)
    if (st /= 0) then
      call fail(cur, 'not enough memory for '//i2s(ntotal)//' nodes', OTHER_FAILURE)
      return
    end if
    d%nnode = 0
    do b = 1, nblock
      edim = get_int(cur, 'an entity dimension')
      etag = get_int(cur, 'an entity tag')
      param = get_int(cur, 'the parametric flag')
      nb = get_int(cur, 'the number of nodes in the block')
      if (cur%info /= 0) return
      if (nb < 0 .or. d%nnode + nb > ntotal) then
        call fail(cur, 'the node blocks hold more nodes than the '//i2s(ntotal)//' announced')
        return
      end if
      first = d%nnode
      do k = first + 1, first + nb
        d%ntag(k) = get_int(cur, 'a node tag')
        if (cur%info /= 0) return
        slot = hash_slot(d%node_hash, int(d%ntag(k), i8))
        if (d%node_hash%key(slot) /= EMPTY) then
          call fail(cur, 'node tag '//i2s(d%ntag(k))//' appears twice')
          return
        end if
        d%node_hash%key(slot) = d%ntag(k)
        d%slot_node(slot) = k
      end do
      do k = first + 1, first + nb
        d%nxy(1, k) = get_real(cur, 'a node x coordinate')
        d%nxy(2, k) = get_real(cur, 'a node y coordinate')
        z = get_real(cur, 'a node z coordinate')
        if (param /= 0) then
          do j = 1, edim
            r = get_real(cur, 'a parametric coordinate')
          end do
        end if
        if (cur%info /= 0) return
        if (z /= 0.0_wp) then
          call fail(cur, 'node '//i2s(d%ntag(k))//' has z = '//trim(real_text(z))// &
                    '; only 2D meshes in the plane z = 0 are read (this is a 3D mesh)')
          return
        end if
      end do
      d%nnode = first + nb
    end do
    if (d%nnode /= ntotal) then
      call fail(cur, 'the node blocks hold '//i2s(d%nnode)//' nodes, not the '//i2s(ntotal)//' announced')
      return
    end if
    call expect(cur, '$EndNodes')
  end subroutine read_nodes

  !> $Elements: triangles and quadrangles (surface entities), lines (curve entities), points.
  subroutine read_elements(cur, d)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(inout) :: d
    integer :: nblock, ntotal, b, edim, etag, etype, nb, k, j, nv, tag, ntg, ent, st, t, slot

    nblock = get_int(cur, 'the number of element blocks')
    ntotal = get_int(cur, 'the number of elements')
    k = get_int(cur, 'the smallest element tag')
    k = get_int(cur, 'the largest element tag')
    if (cur%info /= 0) return
    if (nblock < 0 .or. ntotal < 0) then
      call fail(cur, 'negative numbers of element blocks or elements')
      return
    end if
    ! sized for the worst case; the lines are a small part of a 2D mesh but bounded by ntotal too
    allocate (d%ctag(ntotal), d%cent(ntotal), d%cnode(4, ntotal), d%lent(ntotal), &
              d%lnode(2, ntotal), d%pent(ntotal), d%pnode(ntotal), stat=st)
    if (st /= 0) then
      call fail(cur, 'not enough memory for '//i2s(ntotal)//' elements', OTHER_FAILURE)
      return
    end if
    t = 0
    do b = 1, nblock
      edim = get_int(cur, 'an entity dimension')
      etag = get_int(cur, 'an entity tag')
      etype = get_int(cur, 'an element type')
      nb = get_int(cur, 'the number of elements in the block')
      if (cur%info /= 0) return
      if (nb < 0 .or. t + nb > ntotal) then
        call fail(cur, 'the element blocks hold more elements than the '//i2s(ntotal)//' announced')
        return
      end if
      t = t + nb
      if (edim == 3) then
        call fail(cur, 'has elements of type '//i2s(etype)//' on volume '//i2s(etag)// &
                  ': a 3D mesh, and only 2D meshes are read')
        return
      end if
      select case (etype)
      case (1)
        nv = 2
      case (2)
        nv = 3
      case (3)
        nv = 4
      case (15)
        nv = 1
      case default
        call fail(cur, unsupported_type(etype))
        return
      end select
      ent = entity_index(d, edim, etag)
      do k = 1, nb
        tag = get_int(cur, 'an element tag')
        if (etype == 1) then
          d%nline = d%nline + 1
          d%lent(d%nline) = ent
        else if (etype == 15) then
          d%npoint = d%npoint + 1
          d%pent(d%npoint) = ent
        else
          d%ncell = d%ncell + 1
          d%ctag(d%ncell) = tag
          d%cent(d%ncell) = ent
          d%cnode(:, d%ncell) = 0
        end if
        do j = 1, nv
          ntg = get_int(cur, 'a node tag')
          if (cur%info /= 0) return
          slot = hash_slot(d%node_hash, int(ntg, i8))
          if (d%node_hash%key(slot) == EMPTY) then
            call fail(cur, 'element '//i2s(tag)//' refers to node '//i2s(ntg)//', which is not in $Nodes')
            return
          end if
          if (etype == 1) then
            d%lnode(j, d%nline) = d%slot_node(slot)
          else if (etype == 15) then
            d%pnode(d%npoint) = d%slot_node(slot)
          else
            d%cnode(j, d%ncell) = d%slot_node(slot)
          end if
        end do
      end do
    end do
    if (t /= ntotal) then
      call fail(cur, 'the element blocks hold '//i2s(t)//' elements, not the '//i2s(ntotal)//' announced')
      return
    end if
    call expect(cur, '$EndElements')
  end subroutine read_elements

  !> The sentence refusing an element type.
  function unsupported_type(etype) result(s)
    integer, intent(in) :: etype
    character(len=:), allocatable :: s
    select case (etype)
    case (4, 5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29:35, 92, 93)
      s = 'has 3D elements (type '//i2s(etype)//'), and only 2D meshes are read'
    case (8, 26, 27, 28)
      s = 'has higher-order lines (type '//i2s(etype)//'); use first-order elements '// &
          '(gmsh -order 1, Mesh.ElementOrder = 1)'
    case (9, 20, 21, 22, 23, 24, 25)
      s = 'has higher-order triangles (type '//i2s(etype)//', e.g. 9 = 6-node second order); '// &
          'use first-order elements (gmsh -order 1, Mesh.ElementOrder = 1)'
    case (10, 16, 36, 37, 38)
      s = 'has higher-order quadrangles (type '//i2s(etype)//', e.g. 10 = 9-node second order); '// &
          'use first-order elements (gmsh -order 1, Mesh.ElementOrder = 1)'
    case default
      s = 'has elements of type '//i2s(etype)//'; only first-order lines (1), triangles (2), '// &
          'quadrangles (3) and points (15) are read'
    end select
  end function unsupported_type

  !> The index in d%ent of entity (dim, tag), 0 if it has none (no $Entities).
  integer function entity_index(d, dim, tag) result(k)
    type(msh_data_t), intent(in) :: d
    integer, intent(in) :: dim, tag
    do k = 1, d%nent
      if (d%ent(k)%dim == dim .and. d%ent(k)%tag == tag) return
    end do
    k = 0
  end function entity_index

  !> A real for messages.
  function real_text(x) result(s)
    real(wp), intent(in) :: x
    character(len=24) :: s
    write (s, '(es12.5)') x
    s = adjustl(s)
  end function real_text

  ! ---- the body ---------------------------------------------------------------------------

  !> Choose the body's cells, renumber its nodes, orient and check its cells, find its groups.
  subroutine build_body(cur, d, region, mesh)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(in) :: d
    character(len=*), intent(in) :: region
    type(mesh_t), intent(inout) :: mesh
    integer :: target, k, c, nsurf, nc, st, nq
    logical, allocatable :: in_ent(:)
    integer, allocatable :: sel(:), body_node(:), order(:)
    character(len=:), allocatable :: surfaces

    ! the physical surface of the body
    surfaces = ''
    nsurf = 0
    target = 0
    do k = 1, d%nphys
      if (d%pdim(k) /= 2) cycle
      nsurf = nsurf + 1
      surfaces = surfaces//merge(', ', '  ', nsurf > 1)//"'"//d%pname(k)%s//"'"
      if (len(region) > 0 .and. d%pname(k)%s == region) target = k
    end do
    surfaces = trim(adjustl(surfaces))
    if (len(region) > 0 .and. target == 0) then
      if (nsurf == 0) then
        call fail(cur, "has no physical surface '"//region//"' (it has no physical surfaces)", at_line=.false.)
      else
        call fail(cur, "has no physical surface '"//region//"' (its physical surfaces: "//surfaces//')', &
                  at_line=.false.)
      end if
      return
    end if
    if (len(region) == 0 .and. nsurf > 1) then
      call fail(cur, 'holds '//i2s(nsurf)//' physical surfaces ('//surfaces// &
                '); name the body''s one as its region', at_line=.false.)
      return
    end if
    if (len(region) == 0 .and. nsurf == 1) then
      do k = 1, d%nphys
        if (d%pdim(k) == 2) target = k
      end do
    end if

    ! its cells: those of the surface entities in the group (every one without a group)
    allocate (in_ent(0:d%nent))
    in_ent = target == 0
    do k = 1, d%nent
      if (target > 0) in_ent(k) = d%ent(k)%dim == 2 .and. any(d%ent(k)%phys == d%ptag(target))
    end do
    sel = pack([(c, c=1, d%ncell)], in_ent(d%cent(1:d%ncell)))
    nc = size(sel)
    if (nc == 0) then
      if (target > 0) then
        call fail(cur, "physical surface '"//d%pname(target)%s//"' has no triangles or quadrangles", &
                  at_line=.false.)
      else
        call fail(cur, 'has no triangles or quadrangles', at_line=.false.)
      end if
      return
    end if

    ! its nodes, in increasing tag order
    allocate (body_node(d%nnode), stat=st)
    if (st /= 0) then
      call fail(cur, 'not enough memory', OTHER_FAILURE, .false.)
      return
    end if
    body_node = 0
    do k = 1, nc
      do c = 1, 4
        if (d%cnode(c, sel(k)) > 0) body_node(d%cnode(c, sel(k))) = 1
      end do
    end do
    order = pack([(k, k=1, d%nnode)], body_node > 0)
    call sort_by_tag(order, d%ntag)
    mesh%nnode = size(order)
    allocate (mesh%xy(2, mesh%nnode), mesh%node_tag(mesh%nnode))
    do k = 1, mesh%nnode
      body_node(order(k)) = k
      mesh%xy(:, k) = d%nxy(:, order(k))
      mesh%node_tag(k) = d%ntag(order(k))
    end do

    ! its cells
    nq = count(d%cnode(4, sel) > 0)
    mesh%ncell = nc
    mesh%nvert = merge(4, 3, nq > 0)
    if (nq == nc) then
      mesh%element = ELEM_Q1
    else if (nq == 0) then
      mesh%element = ELEM_P1
    else
      mesh%element = ELEM_MIXED
    end if
    allocate (mesh%cells(mesh%nvert, nc), mesh%cell_type(nc), mesh%cell_tag(nc))
    mesh%cells = 0
    do k = 1, nc
      c = sel(k)
      mesh%cell_tag(k) = d%ctag(c)
      if (d%cnode(4, c) > 0) then
        mesh%cell_type(k) = ELEM_Q1
        mesh%cells(1:4, k) = body_node(d%cnode(1:4, c))
      else
        mesh%cell_type(k) = ELEM_P1
        mesh%cells(1:3, k) = body_node(d%cnode(1:3, c))
      end if
      call orient_cell(cur, mesh, k)
      if (cur%info /= 0) return
    end do

    mesh%structured = .false.
    mesh%source = cur%path
    mesh%nx = 0
    mesh%ny = 0
    mesh%x0 = minval(mesh%xy(1, :))
    mesh%y0 = minval(mesh%xy(2, :))
    mesh%width = maxval(mesh%xy(1, :)) - mesh%x0
    mesh%height = maxval(mesh%xy(2, :)) - mesh%y0

    call boundary_groups(cur, d, body_node, mesh)
    if (cur%info == 0) call point_groups(d, body_node, mesh)
  end subroutine build_body

  !> Put cell k counter-clockwise; refuse it if degenerate or (a quadrangle) not convex.
  subroutine orient_cell(cur, mesh, k)
    type(cursor_t), intent(inout) :: cur
    type(mesh_t), intent(inout) :: mesh
    integer, intent(in) :: k
    real(wp) :: p(2, 4), area2, h2, turn
    integer :: nv, i, i1, i2
    character(len=*), parameter :: what(2) = ['quadrangle', 'triangle  ']

    nv = merge(4, 3, mesh%cell_type(k) == ELEM_Q1)
    p(:, 1:nv) = mesh%xy(:, mesh%cells(1:nv, k))
    area2 = 0.0_wp
    h2 = 0.0_wp
    do i = 1, nv
      i1 = modulo(i, nv) + 1
      area2 = area2 + p(1, i)*p(2, i1) - p(1, i1)*p(2, i)
      h2 = max(h2, sum((p(:, i1) - p(:, i))**2))
    end do
    if (.not. abs(area2) > 2.0_wp*AREA_TOL*h2) then
      call fail(cur, 'element '//i2s(mesh%cell_tag(k))//' (a '//trim(what(mesh%cell_type(k)))// &
                ') is degenerate: its area is zero or nearly so', at_line=.false.)
      return
    end if
    if (area2 < 0.0_wp) then      ! clockwise: reverse, keeping the first vertex
      mesh%cells(2:nv, k) = mesh%cells(nv:2:-1, k)
      p(:, 2:nv) = p(:, nv:2:-1)
    end if
    if (nv == 4) then
      do i = 1, 4
        i1 = modulo(i, 4) + 1
        i2 = modulo(i + 1, 4) + 1
        turn = (p(1, i1) - p(1, i))*(p(2, i2) - p(2, i1)) - (p(2, i1) - p(2, i))*(p(1, i2) - p(1, i1))
        if (.not. turn > AREA_TOL*h2) then
          call fail(cur, 'element '//i2s(mesh%cell_tag(k))//' is not a convex quadrangle '// &
                    '(inverted, self-crossing or with a re-entrant or straight corner at node '// &
                    i2s(mesh%node_tag(mesh%cells(i1, k)))//')', at_line=.false.)
          return
        end if
      end do
    end if
  end subroutine orient_cell

  !> One edge group per physical curve: its lines that are boundary edges of the body, and
  !! the nodes of its lines inside the body as single nodes (a curve inside the body gives
  !! a group of nodes only). The lines' edges are hashed (a small table), then every cell
  !! edge is looked up in it: a line edge met in exactly one cell is a boundary edge,
  !! oriented as that cell has it; one met in two is inside the body.
  subroutine boundary_groups(cur, d, body_node, mesh)
    type(cursor_t), intent(inout) :: cur
    type(msh_data_t), intent(in) :: d
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(mesh_t), intent(inout) :: mesh
    type(hash_t) :: h
    integer, allocatable :: line_slot(:), ecount(:), ecell(:), elocal(:), edges(:, :), cells(:), inner(:)
    logical, allocatable :: on(:)
    integer :: c, i, nv, a, b, slot, st, p, l, ne, ng, ni
    integer(i8) :: key, nn1

    ! the body's line edges, keyed by their two nodes (line_slot = 0: not a body edge)
    call hash_init(h, d%nline, st)
    if (st == 0) allocate (line_slot(d%nline), ecount(0:h%mask), ecell(0:h%mask), elocal(0:h%mask), &
                           edges(2, d%nline), cells(d%nline), inner(2*d%nline), on(mesh%nnode), stat=st)
    if (st /= 0) then
      call fail(cur, 'not enough memory for the boundary edges', OTHER_FAILURE, .false.)
      return
    end if
    line_slot = -1
    ecount = 0
    on = .false.
    nn1 = mesh%nnode + 1
    do l = 1, d%nline
      if (d%lent(l) == 0) cycle
      a = body_node(d%lnode(1, l))
      b = body_node(d%lnode(2, l))
      if (a == 0 .or. b == 0 .or. a == b) cycle
      key = min(a, b)*nn1 + max(a, b)
      slot = hash_slot(h, key)
      h%key(slot) = key
      line_slot(l) = slot
    end do

    ! how many cells have each of them, and the last one
    do c = 1, mesh%ncell
      nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
      do i = 1, nv
        a = mesh%cells(i, c)
        b = mesh%cells(modulo(i, nv) + 1, c)
        key = min(a, b)*nn1 + max(a, b)
        slot = hash_slot(h, key)
        if (h%key(slot) /= key) cycle
        ecount(slot) = ecount(slot) + 1
        ecell(slot) = c
        elocal(slot) = i
      end do
    end do

    mesh%file_groups = ''
    allocate (mesh%group(count(d%pdim(1:d%nphys) == 1 .or. d%pdim(1:d%nphys) == 0)))  ! room for points
    ng = 0
    do p = 1, d%nphys
      if (d%pdim(p) /= 1) cycle
      mesh%file_groups = trim(mesh%file_groups//' '//d%pname(p)%s)
      ne = 0
      ni = 0
      do l = 1, d%nline
        if (line_slot(l) < 0) cycle
        if (.not. any(d%ent(d%lent(l))%phys == d%ptag(p))) cycle
        slot = line_slot(l)
        if (ecount(slot) == 0) cycle          ! not an edge of the body's cells
        if (ecount(slot) > 1) then            ! inside the body: its nodes, once each
          do i = 1, 2
            a = body_node(d%lnode(i, l))
            if (on(a)) cycle
            on(a) = .true.
            ni = ni + 1
            inner(ni) = a
          end do
          cycle
        end if
        c = ecell(slot)
        nv = merge(4, 3, mesh%cell_type(c) == ELEM_Q1)
        ne = ne + 1
        edges(:, ne) = [mesh%cells(elocal(slot), c), mesh%cells(modulo(elocal(slot), nv) + 1, c)]
        cells(ne) = c
      end do
      on(inner(1:ni)) = .false.
      if (ne == 0 .and. ni == 0) cycle
      ng = ng + 1
      mesh%group(ng)%name = d%pname(p)%s
      mesh%group(ng)%nedge = ne
      mesh%group(ng)%edge = edges(:, 1:ne)
      mesh%group(ng)%cell = cells(1:ne)
      mesh%group(ng)%nnode = ni
      mesh%group(ng)%node = inner(1:ni)
    end do
    mesh%file_groups = trim(adjustl(mesh%file_groups))
    mesh%ngroup = ng
  end subroutine boundary_groups

  !> One node group per physical point with nodes in the body, after the edge groups (a
  !! physical point named as a physical curve adds its nodes to the curve's group); the
  !! points' names go to file_groups. A point's node is the body's if the body's cells have
  !! it; a node in no cell of the file is matched to the body's node at its place.
  subroutine point_groups(d, body_node, mesh)
    type(msh_data_t), intent(in) :: d
    integer, intent(in) :: body_node(:)   ! file node index -> body node (0: not in the body)
    type(mesh_t), intent(inout) :: mesh
    logical, allocatable :: in_cell(:)
    integer, allocatable :: nodes(:)
    integer :: p, l, n, nn, g, c, i
    real(wp) :: tol
    character(len=:), allocatable :: names

    names = ''
    allocate (nodes(d%npoint))
    tol = 1.0e-9_wp*max(mesh%width, mesh%height)
    do p = 1, d%nphys
      if (d%pdim(p) /= 0) cycle
      names = names//' '//d%pname(p)%s
      nn = 0
      do l = 1, d%npoint
        if (d%pent(l) == 0) cycle
        if (.not. any(d%ent(d%pent(l))%phys == d%ptag(p))) cycle
        n = body_node(d%pnode(l))
        if (n == 0) then
          if (.not. allocated(in_cell)) then
            allocate (in_cell(d%nnode))
            in_cell = .false.
            do c = 1, d%ncell
              do i = 1, 4
                if (d%cnode(i, c) > 0) in_cell(d%cnode(i, c)) = .true.
              end do
            end do
          end if
          if (.not. in_cell(d%pnode(l))) n = node_at(mesh, d%nxy(:, d%pnode(l)), tol)
        end if
        if (n == 0) cycle
        if (any(nodes(1:nn) == n)) cycle
        nn = nn + 1
        nodes(nn) = n
      end do
      if (nn == 0) cycle
      g = 0
      do c = 1, mesh%ngroup
        if (mesh%group(c)%name == d%pname(p)%s) g = c
      end do
      if (g == 0) then
        mesh%ngroup = mesh%ngroup + 1
        g = mesh%ngroup
        mesh%group(g)%name = d%pname(p)%s
        mesh%group(g)%point = .true.
        allocate (mesh%group(g)%edge(2, 0), mesh%group(g)%cell(0))
      end if
      if (.not. allocated(mesh%group(g)%node)) allocate (mesh%group(g)%node(0))
      mesh%group(g)%node = [mesh%group(g)%node, nodes(1:nn)]
      mesh%group(g)%nnode = size(mesh%group(g)%node)
    end do
    if (len(names) == 0) return
    if (len(mesh%file_groups) == 0) mesh%file_groups = '(none)'
    mesh%file_groups = mesh%file_groups//'; physical points:'//names
  end subroutine point_groups

  !> The body node within tol of xy (the nearest), 0 if none.
  integer function node_at(mesh, xy, tol) result(n)
    type(mesh_t), intent(in) :: mesh
    real(wp), intent(in) :: xy(2), tol
    real(wp) :: dist, best
    integer :: k
    n = 0
    best = tol
    do k = 1, mesh%nnode
      dist = maxval(abs(mesh%xy(:, k) - xy))
      if (dist <= best) then
        n = k
        best = dist
      end if
    end do
  end function node_at

  !> Sort the file node indices `idx` by increasing tag (bottom-up merge sort).
  subroutine sort_by_tag(idx, tag)
    integer, intent(inout) :: idx(:)
    integer, intent(in) :: tag(:)
    integer, allocatable :: work(:)
    integer :: n, width, lo, mid, hi, i, j, k
    n = size(idx)
    if (n < 2) return
    if (all(tag(idx(2:n)) > tag(idx(1:n - 1)))) return     ! the usual case: already sorted
    allocate (work(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width, n + 1)
        hi = min(lo + 2*width, n + 1)
        i = lo
        j = mid
        do k = lo, hi - 1
          if (i < mid .and. (j >= hi .or. tag(idx(min(i, n))) <= tag(idx(min(j, n))))) then
            work(k) = idx(i)
            i = i + 1
          else
            work(k) = idx(j)
            j = j + 1
          end if
        end do
      end do
      idx = work
      width = 2*width
    end do
  end subroutine sort_by_tag

end module gmsh_msh
