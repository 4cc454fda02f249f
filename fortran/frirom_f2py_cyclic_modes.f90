! A cyclic sector's nonlinear mode on the run object for f2py (frirom_run
! run_set_nonlinear_mode_cyclic), under the rules of frirom_f2py_run.f90: plain
! subroutines, explicit-shape arrays, real(8) / integer(4) dummies, `info` plus the
! library's message.

!> A run opened with mode 3 and formulation 1 on a cyclic sector's packed rows: psi (ndof,
!> nm, nh1) complex shapes of each harmonic's nodal diameter (nh1 = H + 1), wmodes, zmodes
!> (nm, nh1) rad/s and ratios, the linear mode it starts from as modal coordinates q0 (nm)
!> of harmonic 1's modes and its frequency omega0 (rad/s). Out: ny, the unknowns per point.
subroutine frun_set_nonlinear_mode_cyclic(handle, ndof, nm, nh1, q0, omega0, psi, wmodes, &
                                          zmodes, ny, info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_cyc => run_set_nonlinear_mode_cyclic
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: ndof, nm, nh1
    complex(8), intent(in) :: q0(nm), psi(ndof, nm, nh1)
    real(8), intent(in) :: omega0, wmodes(nm, nh1), zmodes(nm, nh1)
    integer(4), intent(out) :: ny, info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    msg = ''
    ny = 0
    call run_from_handle(handle, r, 'run_set_nonlinear_mode_cyclic', linfo, msg)
    if (linfo == 0) call fr_cyc(r, q0, omega0, psi, wmodes, zmodes, linfo, msg)
    if (linfo == 0) ny = int(r%ny, 4)
    info = linfo
end subroutine frun_set_nonlinear_mode_cyclic
