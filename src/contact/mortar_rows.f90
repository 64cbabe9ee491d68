!> The contract of a mortar coupling, whatever the dimension: what a mortar implementation
!! delivers for one contact pair and what the contact interface reads from it. One row per
!! slave node that carries a multiplier, the weighted normal gap constraint
!!
!!     sum_k ws_k n_j.u^s_k - sum_l wm_l n_j.u^m_l <= g0_j,
!!     ws_k = int Phi_j N_k / D_jj,  wm_l = M_jl / D_jj,  D_jj = int N_j,
!!
!! the integrals over the slave contact curve (2D, module mortar_segments) or surface (3D),
!! Phi_j the dual basis of the slave shape functions N_j, N^m_l the master ones composed with
!! the projection along the slave normal. Every implementation guarantees:
!! - the rows' own slave weight comes first in each row's slave entries, and a fully covered
!!   row whose dual function was not modified has that single slave entry, of weight 1;
!! - sum_k ws_k = sum_l wm_l on every row (a rigid translation opens no gap);
!! - n_j is the averaged unit normal at the slave node, outward from the slave body, and the
!!   row's tangents follow from it (module space, frame_of);
!! - g0_j is the row at u = 0 (the weighted initial gap).
!! `mortar_consistency` measures the second statement's companion on fully covered rows,
!! max |sum_l M_jl - D_jj| / D_jj (0 to rounding on flat matching meshes).
module mortar_rows
  use kinds, only: wp
  implicit none (type, external)
  private

  !> The constraint rows of one contact pair (weights already divided by D_jj), in the slave
  !! implementation's order (2D: along the slave chain).
  type, public :: mortar_t
    integer :: m = 0                          !< rows (slave nodes with a multiplier)
    integer, allocatable :: snode(:)          !< (m) the slave node of each row (slave body's node id)
    real(wp), allocatable :: normal(:, :)     !< (NDIM,m) averaged unit normal at the slave node, outward from the slave body
    real(wp), allocatable :: d(:)             !< (m) D_jj [length^(NDIM-1)] (tributary length or area on the slave side)
    real(wp), allocatable :: s(:)             !< (m) 2D: arc length of the slave node from the chain's first node [length]; 3D: 0
    real(wp), allocatable :: g0(:)            !< (m) initial weighted normal gap [length] (>= 0 expected; can be < 0)
    integer, allocatable :: sptr(:)           !< (m+1) CSR pointers of the slave entries (row j: sptr(j) .. sptr(j+1)-1)
    integer, allocatable :: snod(:)           !< slave node ids (the row's own node first)
    real(wp), allocatable :: sval(:)          !< slave weights int Phi_j N_k / D_jj [1]
    integer, allocatable :: mptr(:)           !< (m+1) CSR pointers of the master entries
    integer, allocatable :: mnod(:)           !< master node ids
    real(wp), allocatable :: mval(:)          !< master weights M_jl / D_jj [1]
  end type mortar_t

  public :: mortar_consistency

contains

  !> max |sum_l M_jl - D_jj| / D_jj = max |sum_l wm_l - 1| over the fully covered, unmodified
  !! rows (a single slave entry, of weight 1 to 1e-12); nfull = their count (0: the value is 0).
  pure subroutine mortar_consistency(mt, dev, nfull)
    type(mortar_t), intent(in) :: mt
    real(wp), intent(out) :: dev              !< the largest relative deviation [-]
    integer, intent(out) :: nfull             !< rows measured
    integer :: j
    dev = 0.0_wp
    nfull = 0
    do j = 1, mt%m
      if (mt%sptr(j + 1) - mt%sptr(j) /= 1) cycle
      if (abs(mt%sval(mt%sptr(j)) - 1.0_wp) > 1.0e-12_wp) cycle
      nfull = nfull + 1
      dev = max(dev, abs(sum(mt%mval(mt%mptr(j):mt%mptr(j + 1) - 1)) - 1.0_wp))
    end do
  end subroutine mortar_consistency

end module mortar_rows
