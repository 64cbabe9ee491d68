!> The linear system of one body on its free DOFs, as module assembly builds it: the DOF
!! numbering, the stiffness in compressed sparse columns, the load, and the rigid motions
!! left free by the supports of a body held only by contact (module rigid_modes).
!!
!! DOFs: node k, component c (1 = x, 2 = y) is global dof 2*(k-1)+c.
module body_system
  use kinds, only: wp
  implicit none (type, external)
  private

  !> The linear system of one body on its free DOFs.
  type, public :: body_system_t
    integer :: id = 0                         !< body id
    integer :: ndof = 0                       !< 2*nnode
    integer :: n = 0                          !< number of free (unknown) DOFs
    integer, allocatable :: free_of(:)        !< (ndof) free index 1..n, or 0 if prescribed
    integer, allocatable :: dof_of(:)         !< (n) global dof of each free index
    real(wp), allocatable :: u_fixed(:)       !< (ndof) prescribed displacements, 0 at free dofs [length]
    integer, allocatable :: colptr(:)         !< (n+1) 0-based CSC column pointers of K (free dofs, both triangles)
    integer, allocatable :: rowind(:)         !< (nnz) 0-based row indices, sorted within each column
    real(wp), allocatable :: val(:)           !< (nnz) stiffness entries [stress] (force/length per unit thickness)
    real(wp), allocatable :: f(:)             !< (n) load on free dofs incl. the lifting -K_fd u_d [force]
    !> (ndof) applied nodal loads (tractions, optional body force), all dofs [force]
    real(wp), allocatable :: f_applied(:)
    real(wp) :: k_norm = 0.0_wp               !< max abs row sum of K (infinity norm) [stress]
    !> The loads by stage, for load steps (allocated when the assembly is asked for them):
    !! f, u_fixed and f_applied are linear in the loads, so a step's are the sum of the
    !! earlier stages' columns plus its load factor times its own stage's
    integer :: nstage = 0                     !< stages assembled (0: none)
    integer, allocatable :: dof_stage(:)      !< (ndof) stage of each prescribed value (0: free or a support)
    real(wp), allocatable :: f_stage(:, :)    !< (n, nstage) each stage's f, its lifting included [force]
    real(wp), allocatable :: u_stage(:, :)    !< (ndof, nstage) each stage's prescribed values [length]
    real(wp), allocatable :: fa_stage(:, :)   !< (ndof, nstage) each stage's applied loads [force]
    !> A body whose prescribed displacements leave rigid motions free (held only by
    !! contact, doc/method.md, "Bodies held only by contact"): nrig > 0 kernel vectors R of K, and
    !! as many fixing DOFs, prescribed to 0 in the factorized system only, so that the
    !! factor is a generalized inverse K^+ (K K^+ K = K) and u = K^+ (f - B'lam) + R alpha
    integer :: nrig = 0                       !< rigid motions left free (0..3)
    real(wp), allocatable :: rig(:, :)        !< (ndof, nrig) kernel of K, zero at prescribed DOFs [length/length]
    !> (NRIGID, nrig) each column in the basis of rigid motions: the translations along the
    !! axes, then the rotations about them through rig_xc over rig_h (in the plane (1,0), (0,1),
    !! (-(y-yc), x-xc)/h; in space e_k and e_k x (x - xc)/h, k = x, y, z)
    real(wp), allocatable :: rig_coef(:, :)
    real(wp) :: rig_xc(3) = 0.0_wp            !< centre of the rotation basis (NDIM used) [length]
    real(wp) :: rig_h = 1.0_wp                !< scale of the rotation basis (largest extent) [length]
    integer, allocatable :: fixing(:)         !< (nrig) the fixing DOFs (global dof numbers)
    real(wp) :: rig_residual = 0.0_wp         !< max |K R| / (k_norm max |R|), the check of the kernel
  end type body_system_t

end module body_system
