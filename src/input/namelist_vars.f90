!> The variable tables of namelist groups: each group is read against a table of the
!! variables it may set (`vars_t`: name, type, and a pointer to where the value lives).
!! The same table renders the group back as namelist text (`render_group`) and documents
!! it as a Markdown table (`reference_table`: each entry may carry a description, a unit
!! and the allowed range). The reader (`namelist_input`) checks assignments against it.
module namelist_vars
  use kinds, only: wp
  use strings, only: i2s, roundtrip, quote, word
  implicit none (type, external)
  private

  character(len=*), parameter :: NL = achar(10)

  !> Types of a table entry.
  integer, parameter, public :: T_INT = 1, T_REAL = 2, T_STR = 3, T_ENUM = 4

  !> A variable-length string (for arrays of them).
  type, public :: str_t
    character(len=:), allocatable :: s
  end type str_t

  !> A pointer to one string (an element of a string pair's storage).
  type :: strp_t
    character(len=:), pointer :: p => null()
  end type strp_t

  !> One variable of a group, bound to the place its value lives.
  type, public :: var_t
    character(len=:), allocatable :: name
    integer :: typ = 0                          ! T_*
    integer :: nval = 1                         ! values it takes (1, or 2 for pairs)
    integer, pointer :: ip => null()            ! T_INT, T_ENUM (the code)
    integer, pointer :: iv(:) => null()         ! T_INT, nval values
    real(wp), pointer :: rs => null()           ! T_REAL, one value
    real(wp), pointer :: rv(:) => null()        ! T_REAL, nval values
    character(len=:), pointer :: sp => null()   ! T_STR, one value
    type(strp_t), allocatable :: sv(:)          ! T_STR, nval values
    character(len=:), allocatable :: choices    ! T_ENUM: allowed spellings, in code order
    integer :: base = 1                         ! T_ENUM: code of the first choice
    character(len=:), allocatable :: doc        ! description (Markdown), for the reference
    character(len=:), allocatable :: unit       ! unit in the deck's terms, e.g. '[length]'
    character(len=:), allocatable :: range      ! the values the checks accept, e.g. '> 0'
    logical :: required = .false.               ! the group needs it (no default)
    integer :: unset = 0                        ! T_INT list (nval > 2): the value of an entry not given
  end type var_t

  !> The variables of one group, each bound to its storage (which must outlive the table).
  type, public :: vars_t
    integer :: n = 0
    type(var_t), allocatable :: v(:)
  contains
    procedure :: int => add_int       !< an integer
    procedure :: real => add_real     !< a real
    procedure :: pair => add_pair     !< a vector of reals (x and y components, or x, y and z)
    procedure :: ints => add_ints     !< two integers
    procedure :: list => add_list     !< a list of integers, as many as given
    procedure :: str => add_str       !< a quoted string
    procedure :: strs => add_strs     !< two quoted strings
    procedure :: enum => add_enum     !< a quoted string from a list, stored as its code
    procedure :: has => has_var       !< whether the table holds a variable of that name
  end type vars_t

  public :: render_group, reference_table, var_index, var_list

contains


  !> Append an entry `name` of type `typ` (T_*); the caller binds it to its storage.
  subroutine push(self, name, typ)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name
    integer, intent(in) :: typ
    type(var_t), allocatable :: tmp(:)
    if (.not. allocated(self%v)) allocate (self%v(16))
    if (self%n == size(self%v)) then
      allocate (tmp(2*self%n))
      tmp(1:self%n) = self%v(1:self%n)
      call move_alloc(tmp, self%v)
    end if
    self%n = self%n + 1
    self%v(self%n)%name = name
    self%v(self%n)%typ = typ
  end subroutine push

  !> The documentation of a table entry (all optional): what it is, its unit, the values the
  !! group's checks accept, and whether the group needs it. Absent ones stay unallocated
  !! (read through `text_of`): tables are built for every group read, documented or not.
  subroutine describe(v, doc, unit, range, required)
    type(var_t), intent(inout) :: v
    character(len=*), intent(in), optional :: doc, unit, range
    logical, intent(in), optional :: required
    if (present(doc)) v%doc = doc
    if (present(unit)) v%unit = unit
    if (present(range)) v%range = range
    if (present(required)) v%required = required
  end subroutine describe

  !> An optional text of a table entry, '' when it was not given.
  pure function text_of(s) result(t)
    character(len=:), allocatable, intent(in) :: s
    character(len=:), allocatable :: t
    t = ''
    if (allocated(s)) t = s
  end function text_of

  subroutine add_int(self, name, x, doc, range, required)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    integer, target, intent(inout) :: x       !< its storage
    character(len=*), intent(in), optional :: doc       !< description
    character(len=*), intent(in), optional :: range     !< accepted values, e.g. '>= 1'
    logical, intent(in), optional :: required           !< no default: the group needs it
    call push(self, name, T_INT)
    self%v(self%n)%ip => x
    call describe(self%v(self%n), doc=doc, range=range, required=required)
  end subroutine add_int

  subroutine add_real(self, name, x, doc, unit, range)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    real(wp), target, intent(inout) :: x      !< its storage
    character(len=*), intent(in), optional :: doc       !< description
    character(len=*), intent(in), optional :: unit      !< unit, e.g. '[length]', '[-]'
    character(len=*), intent(in), optional :: range     !< accepted values, e.g. '> 0'
    call push(self, name, T_REAL)
    self%v(self%n)%rs => x
    call describe(self%v(self%n), doc=doc, unit=unit, range=range)
  end subroutine add_real

  subroutine add_pair(self, name, x, doc, unit)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    real(wp), target, intent(inout) :: x(:)   !< its storage (x and y components, or x, y and z)
    character(len=*), intent(in), optional :: doc       !< description
    character(len=*), intent(in), optional :: unit      !< unit of every component
    call push(self, name, T_REAL)
    self%v(self%n)%nval = size(x)
    self%v(self%n)%rv => x
    call describe(self%v(self%n), doc=doc, unit=unit)
  end subroutine add_pair

  subroutine add_ints(self, name, x, doc, range, required)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    integer, target, intent(inout) :: x(2)    !< its storage
    character(len=*), intent(in), optional :: doc       !< description
    character(len=*), intent(in), optional :: range     !< accepted values
    logical, intent(in), optional :: required           !< no default: the group needs it
    call push(self, name, T_INT)
    self%v(self%n)%nval = 2
    self%v(self%n)%iv => x
    call describe(self%v(self%n), doc=doc, range=range, required=required)
  end subroutine add_ints

  !> A list of up to size(x) integers; the entries not given hold `unset` and are neither
  !! rendered nor shown as defaults.
  subroutine add_list(self, name, x, unset, doc, range)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    integer, target, intent(inout) :: x(:)    !< its storage
    integer, intent(in) :: unset              !< the value of an entry not given
    character(len=*), intent(in), optional :: doc       !< description
    character(len=*), intent(in), optional :: range     !< accepted values
    call push(self, name, T_INT)
    self%v(self%n)%nval = size(x)
    self%v(self%n)%iv => x
    self%v(self%n)%unset = unset
    call describe(self%v(self%n), doc=doc, range=range)
  end subroutine add_list

  !> The given entries of an integer list, comma-separated.
  function list_text(v) result(s)
    type(var_t), intent(in) :: v
    character(len=:), allocatable :: s
    integer :: k
    s = ''
    do k = 1, v%nval
      if (v%iv(k) == v%unset) exit
      if (k > 1) s = s//', '
      s = s//i2s(v%iv(k))
    end do
  end function list_text

  subroutine add_strs(self, name, x, doc, required)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name                 !< variable name (lower case)
    character(len=*), target, intent(inout) :: x(2)      !< its storage (its length is the limit)
    character(len=*), intent(in), optional :: doc        !< description
    logical, intent(in), optional :: required            !< no default: the group needs it
    integer :: k
    call push(self, name, T_STR)
    self%v(self%n)%nval = 2
    allocate (self%v(self%n)%sv(2))
    do k = 1, 2
      self%v(self%n)%sv(k)%p => x(k)
    end do
    call describe(self%v(self%n), doc=doc, required=required)
  end subroutine add_strs

  subroutine add_str(self, name, x, doc, required)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name              !< variable name (lower case)
    character(len=*), target, intent(inout) :: x      !< its storage (its length is the limit)
    character(len=*), intent(in), optional :: doc     !< description
    logical, intent(in), optional :: required         !< no default: the group needs it
    call push(self, name, T_STR)
    self%v(self%n)%sp => x
    call describe(self%v(self%n), doc=doc, required=required)
  end subroutine add_str

  subroutine add_enum(self, name, x, choices, base, doc, required)
    class(vars_t), intent(inout) :: self
    character(len=*), intent(in) :: name      !< variable name (lower case)
    integer, target, intent(inout) :: x       !< its storage: the code of the choice
    character(len=*), intent(in) :: choices   !< allowed spellings, blank-separated, in code order
    integer, intent(in), optional :: base     !< code of the first choice (default 1)
    character(len=*), intent(in), optional :: doc   !< description
    logical, intent(in), optional :: required       !< no default: the group needs it
    call push(self, name, T_ENUM)
    self%v(self%n)%ip => x
    self%v(self%n)%choices = choices
    if (present(base)) self%v(self%n)%base = base
    call describe(self%v(self%n), doc=doc, required=required)
  end subroutine add_enum

  !> Whether the table holds a variable `name`.
  logical function has_var(self, name)
    class(vars_t), intent(in) :: self
    character(len=*), intent(in) :: name   !< variable name (lower case)
    has_var = var_index(self, name) > 0
  end function has_var

  integer function var_index(vars, name)
    type(vars_t), intent(in) :: vars
    character(len=*), intent(in) :: name
    integer :: k
    var_index = 0
    do k = 1, vars%n
      if (vars%v(k)%name == name) then
        var_index = k
        return
      end if
    end do
  end function var_index

  function var_list(vars) result(s)
    type(vars_t), intent(in) :: vars
    character(len=:), allocatable :: s
    integer :: k
    s = ''
    do k = 1, vars%n
      if (k > 1) s = s//', '
      s = s//vars%v(k)%name
    end do
  end function var_list

  !> The group as namelist text, `&name var=value, ... /`, wrapped before `width` columns.
  function render_group(name, vars, width) result(text)
    character(len=*), intent(in) :: name   !< group name
    type(vars_t), intent(in) :: vars       !< its variables and their current values
    integer, intent(in) :: width           !< wrap lines before this many characters
    character(len=:), allocatable :: text
    character(len=:), allocatable :: item, line
    integer :: k
    text = ''
    line = '&'//name
    do k = 1, vars%n
      associate (v => vars%v(k))
        select case (v%typ)
        case (T_INT)
          if (v%nval == 1) then
            item = v%name//'='//i2s(v%ip)
          else if (v%nval > 2) then
            item = v%name//'='//list_text(v)
          else
            item = v%name//'='//i2s(v%iv(1))//', '//i2s(v%iv(2))
          end if
        case (T_REAL)
          if (v%nval == 1) then
            item = v%name//'='//roundtrip(v%rs)
          else
            item = v%name//'='//roundtrip(v%rv(1))//', '//roundtrip(v%rv(2))
            if (v%nval == 3) item = item//', '//roundtrip(v%rv(3))
          end if
        case (T_STR)
          if (v%nval == 1) then
            item = v%name//'='//quote(trim(v%sp))
          else
            item = v%name//'='//quote(trim(v%sv(1)%p))//', '//quote(trim(v%sv(2)%p))
          end if
        case default
          item = v%name//'='//quote(word(v%choices, v%ip - v%base + 1))
        end select
      end associate
      if (k < vars%n) item = item//','
      if (len(line) + 1 + len(item) > width .and. len(line) > 6) then
        text = text//line//NL
        line = '      '//item
      else
        line = line//' '//item
      end if
    end do
    text = text//line//' /'//NL
  end function render_group

  !> The group's variables as a Markdown table: variable, type, default (the current values
  !! of the storage the table is bound to), unit, allowed values, description. With `forms`,
  !! the tables of the group's forms (a rectangle and a mesh file, say), a variable that only
  !! some of them hold has their names (`form_names`) before its description.
  function reference_table(vars, forms, form_names) result(text)
    type(vars_t), intent(in) :: vars                  !< the group's variables (all forms)
    type(vars_t), intent(in), optional :: forms(:)    !< the variables of each form
    type(str_t), intent(in), optional :: form_names(:) !< the name of each form
    character(len=:), allocatable :: text
    character(len=:), allocatable :: typ, def, allowed, only
    integer :: k, f, j
    text = '| variable | type | default | unit | allowed values | description |'//NL// &
           '| --- | --- | --- | --- | --- | --- |'//NL
    do k = 1, vars%n
      associate (v => vars%v(k))
        allowed = text_of(v%range)
        select case (v%typ)
        case (T_INT)
          if (v%nval == 1) then
            typ = 'integer'
            def = '`'//i2s(v%ip)//'`'
          else if (v%nval > 2) then
            typ = 'integer list (at most '//i2s(v%nval)//')'
            def = '`'//list_text(v)//'`'
          else
            typ = 'integer pair'
            def = '`'//i2s(v%iv(1))//', '//i2s(v%iv(2))//'`'
          end if
        case (T_REAL)
          if (v%nval == 1) then
            typ = 'real'
            def = '`'//roundtrip(v%rs)//'`'
            if (v%rs == -huge(1.0_wp)) def = 'not given'
          else
            typ = 'real pair (x, y)'
            def = '`'//roundtrip(v%rv(1))//', '//roundtrip(v%rv(2))//'`'
            if (v%nval == 3) then
              typ = 'real vector (x, y, z)'
              def = '`'//roundtrip(v%rv(1))//', '//roundtrip(v%rv(2))//', '//roundtrip(v%rv(3))//'`'
            end if
          end if
        case (T_STR)
          if (v%nval == 1) then
            typ = 'string (at most '//i2s(len(v%sp))//' characters)'
            def = '`'//quote(trim(v%sp))//'`'
          else
            typ = 'string pair (at most '//i2s(len(v%sv(1)%p))//' characters each)'
            def = '`'//quote(trim(v%sv(1)%p))//', '//quote(trim(v%sv(2)%p))//'`'
          end if
        case default
          typ = 'choice'
          j = v%ip - v%base + 1
          def = 'none'
          if (j >= 1) then
            if (len(word(v%choices, j)) > 0) def = '`'//quote(word(v%choices, j))//'`'
          end if
          allowed = ''
          j = 1
          do while (len(word(v%choices, j)) > 0)
            if (j > 1) allowed = allowed//', '
            allowed = allowed//'`'//quote(word(v%choices, j))//'`'
            j = j + 1
          end do
        end select
        if (v%required) def = 'required'
        only = ''
        if (present(forms) .and. present(form_names)) then
          j = count([(forms(f)%has(v%name), f = 1, size(forms))])
          if (j > 0 .and. j < size(forms)) then
            do f = 1, size(forms)
              if (.not. forms(f)%has(v%name)) cycle
              if (len(only) > 0) only = only//' or '
              only = only//form_names(f)%s
            end do
            only = '*'//only//' only:* '
          end if
        end if
        text = text//'| `'//v%name//'` |'//cell(typ)//cell(def)//cell(text_of(v%unit))//cell(allowed)// &
               cell(only//text_of(v%doc))//NL
      end associate
    end do
  contains
    ! one cell of a Markdown table row and the bar after it ('|' in the text escaped)
    function cell(s) result(c)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: c
      integer :: i
      c = ''
      do i = 1, len(s)
        if (s(i:i) == '|') c = c//'\'
        c = c//s(i:i)
      end do
      if (len(c) > 0) c = ' '//c
      c = c//' |'
    end function cell
  end function reference_table

end module namelist_vars
