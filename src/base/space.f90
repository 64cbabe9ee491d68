!> The spatial dimension and what follows from it, named once: the coordinates of a node, the
!! components of its displacement, the rigid motions of a free body, the stress components a
!! node carries, and the numbering of the DOFs (node k, component c is DOF NCOMP (k - 1) + c,
!! the components of a node consecutive). Every body is plane today (plane strain, plane
!! stress, or the meridian section of a body of revolution) or solid; a module that depends on
!! the dimension says so through these names, not through a literal 2, 3 or 4. The dimension
!! is the run's, set once (`set_dimension`) when the deck is read: one binary solves plane
!! and solid scenes.
module space
  use kinds, only: wp
  implicit none (type, external)
  private

  ! Set once per run by set_dimension (the deck's dimension), read everywhere else.
  integer, protected, public :: NDIM = 2       !< coordinates of a node: (x, y), or (x, y, z)
  integer, protected, public :: NCOMP = 2      !< displacement components of a node: NDIM
  integer, protected, public :: NRIGID = 3     !< rigid motions of a free body, NDIM (NDIM + 1) / 2: translations and rotations
  !> stress components of a node: in the plane sxx, syy, sxy and szz; in space sxx, syy, szz,
  !! syz, sxz, sxy (Voigt order)
  integer, protected, public :: NSTRESS = 4

  public :: set_dimension, node_dof, dof_node, dof_comp, frame_of

contains

  !> Set the run's dimension: 2 (plane and axisymmetric bodies) or 3 (solid bodies). Any
  !! other value leaves it unchanged (the deck has refused it before).
  subroutine set_dimension(d)
    integer, intent(in) :: d             !< 2 or 3
    if (d /= 2 .and. d /= 3) return
    NDIM = d
    NCOMP = d
    NRIGID = d*(d + 1)/2
    NSTRESS = merge(4, 6, d == 2)
  end subroutine set_dimension

  !> The DOF of node k's component c: NCOMP (k - 1) + c.
  elemental integer function node_dof(k, c)
    integer, intent(in) :: k   !< the node, 1..nnode
    integer, intent(in) :: c   !< the component, 1..NCOMP (1 = x, 2 = y, 3 = z)
    node_dof = NCOMP*(k - 1) + c
  end function node_dof

  !> The node of DOF i.
  elemental integer function dof_node(i)
    integer, intent(in) :: i   !< a DOF, 1..NCOMP nnode
    dof_node = (i - 1)/NCOMP + 1
  end function dof_node

  !> The component of DOF i (1 = x, 2 = y, 3 = z).
  elemental integer function dof_comp(i)
    integer, intent(in) :: i   !< a DOF, 1..NCOMP nnode
    dof_comp = i - NCOMP*((i - 1)/NCOMP)
  end function dof_comp

  !> The frame of a contact node with unit normal n: the columns n, then size(n) - 1 unit
  !! tangents, orthonormal and right-handed. In the plane the tangent is (-n_y, n_x); in space
  !! t1 is n x e_k normalized, e_k the axis along which n is smallest, and t2 = n x t1.
  pure function frame_of(n) result(f)
    real(wp), intent(in) :: n(:)                  !< the unit normal (NDIM)
    real(wp) :: f(size(n), size(n))               !< (NDIM, NDIM) the frame, column 1 = n
    real(wp) :: e(3), t(3)
    f(:, 1) = n
    if (size(n) == 2) then
      f(1, 2) = -n(2)
      f(2, 2) = n(1)
    else if (size(n) == 3) then
      e = 0.0_wp
      e(minloc(abs(n), dim=1)) = 1.0_wp
      t = [n(2)*e(3) - n(3)*e(2), n(3)*e(1) - n(1)*e(3), n(1)*e(2) - n(2)*e(1)]
      t = t/norm2(t)
      f(:, 2) = t
      f(:, 3) = [n(2)*t(3) - n(3)*t(2), n(3)*t(1) - n(1)*t(3), n(1)*t(2) - n(2)*t(1)]
    end if
  end function frame_of

end module space
