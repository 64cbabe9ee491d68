!> Mortar coupling of a contact pair behind one entry point: `mortar_build` takes the slave
!! and master contact faces (2D: edges of 2 nodes; 3D: triangles and quadrilaterals) with
!! their bodies' node coordinates and returns the rows of module mortar_rows's contract,
!! whatever the dimension. The plane implementation is module mortar_segments
!! (segment-based integration along the slave chain), the surface one module
!! mortar_surfaces (segment-based integration on each slave face's auxiliary plane); the
!! coordinates' dimension and the faces' rows pick one.
module mortar
  use kinds, only: wp
  use strings, only: i2s
  use errors, only: error_t, ERR_INPUT
  use mortar_rows, only: mortar_t, mortar_consistency
  use mortar_segments, only: segment_mortar
  use mortar_surfaces, only: surface_mortar
  implicit none (type, external)
  private

  public :: mortar_t, mortar_build, mortar_consistency

contains

  !> The dual mortar rows of a slave contact group against a master one. err (ERR_INPUT,
  !! naming the side and the face or node) on bad input, or when no slave node ends up with a
  !! row (no overlap, master faces facing away, all removable).
  subroutine mortar_build(xs, fs, removable, xm, fm, mt, err, tag_s, tag_m, axisymmetric)
    real(wp), intent(in) :: xs(:, :)        !< (NDIM, nnode_s) slave body node coordinates [length]
    !> (nvf, nf_s) slave contact faces (node ids): 2D edges with the body on their left; 3D rows of
    !! 4 (quadrilateral, or a triangle with a 0 in row 4) or 3 (triangles), counter-clockwise seen
    !! from outside the body
    integer, intent(in) :: fs(:, :)
    logical, intent(in) :: removable(:)     !< (nnode_s) the slave node may carry no multiplier (normal displacement prescribed on both bodies)
    real(wp), intent(in) :: xm(:, :)        !< (NDIM, nnode_m) master body node coordinates [length]
    integer, intent(in) :: fm(:, :)         !< (nvf, nf_m) master contact faces
    type(mortar_t), intent(out) :: mt       !< the constraint rows
    type(error_t), intent(out) :: err       !< the bad input, if any
    integer, intent(in), optional :: tag_s(:), tag_m(:)   !< (nnode_s), (nnode_m) node tags for messages
    !> meridian sections of bodies of revolution (x = r): every integral per radian, r-weighted
    logical, intent(in), optional :: axisymmetric
    if (size(xs, 1) /= size(xm, 1)) then
      call err%set(ERR_INPUT, 'mortar: the slave nodes have '//i2s(size(xs, 1))//' coordinates and the master '// &
                   'nodes '//i2s(size(xm, 1)))
    else if (size(xs, 1) == 2 .and. size(fs, 1) == 2 .and. size(fm, 1) == 2) then
      call segment_mortar(xs, fs, removable, xm, fm, mt, err, tag_s, tag_m, axisymmetric)
    else if (size(xs, 1) == 3 .and. (size(fs, 1) == 3 .or. size(fs, 1) == 4) .and. &
             (size(fm, 1) == 3 .or. size(fm, 1) == 4)) then
      if (present(axisymmetric)) then
        if (axisymmetric) then
          call err%set(ERR_INPUT, 'mortar: axisymmetric applies to meridian sections (2-coordinate nodes), '// &
                       'not to 3-coordinate ones')
          return
        end if
      end if
      call surface_mortar(xs, four_rows(fs), removable, xm, four_rows(fm), mt, err, tag_s, tag_m)
    else
      call err%set(ERR_INPUT, 'mortar: no mortar for '//i2s(size(xs, 1))//'-coordinate nodes with faces of '// &
                   i2s(size(fs, 1))//' (slave) and '//i2s(size(fm, 1))//' (master) nodes')
    end if
  end subroutine mortar_build

  !> A face array with 4 rows: a 3-row one (triangles) padded with a row of 0.
  pure function four_rows(f) result(f4)
    integer, intent(in) :: f(:, :)          !< (3 or 4, nface) faces (node ids)
    integer :: f4(4, size(f, 2))
    f4 = 0
    f4(1:size(f, 1), :) = f
  end function four_rows

end module mortar
