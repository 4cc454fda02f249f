! Nonlinear modes on the run object for f2py (frirom_run run_set_nonlinear_mode), under the
! rules of frirom_f2py_run.f90: plain subroutines, explicit-shape arrays, real(8) /
! integer(4) dummies, `info` plus the library's message.

!> A run opened with mode 3 (nonlinear mode): the linear mode phi (ndof) and its natural
!> frequency omega0 (rad/s) the EPMC starts from; a condensed run (formulation 1) the nm
!> modes of its receptances (modal = 1: modes, wm rad/s, zm ratios; modal = 0, a banded
!> run: 1-column dummies). Out:
!> ny, the unknowns per point (rows (2H+1) + 2: the harmonics of every DoF or of the
!> contact DoFs, omega / omega0, xi / omega0).
subroutine frun_set_nonlinear_mode(handle, ndof, phi, omega0, modal, nm, modes, wm, zm, ny, &
                                   info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_nlm => run_set_nonlinear_mode
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: ndof, modal, nm
    real(8), intent(in) :: phi(ndof), omega0, modes(ndof, nm), wm(nm), zm(nm)
    integer(4), intent(out) :: ny, info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    msg = ''
    ny = 0
    call run_from_handle(handle, r, 'run_set_nonlinear_mode', linfo, msg)
    if (linfo == 0 .and. modal == 1) then
        call fr_nlm(r, phi, omega0, linfo, msg, modes=modes, wm=wm, zm=zm)
    else if (linfo == 0) then
        call fr_nlm(r, phi, omega0, linfo, msg)
    end if
    if (linfo == 0) ny = int(r%ny, 4)
    info = linfo
end subroutine frun_set_nonlinear_mode

!> The residual r, dR/dlam and the Jacobian jm (unfactorised) of a mode run at the
!> unknowns y and lam = log10 a (checks against finite differences; the run's contact
!> history is the one the AFT starts from).
subroutine frun_mode_jacobian(handle, lam, ny, y, r, rlam, jm, info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle
    use frirom_epmc, only: hbm_epmc_jacobian
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: ny
    real(8), intent(in) :: lam, y(ny)
    real(8), intent(out) :: r(ny), rlam(ny), jm(ny, ny)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: rn
    integer(ip) :: linfo
    msg = ''
    r = 0.0d0
    rlam = 0.0d0
    jm = 0.0d0
    call run_from_handle(handle, rn, 'frun_mode_jacobian', linfo, msg)
    if (linfo == 0) call hbm_epmc_jacobian(rn%sys, y, lam, r, rlam, jm, linfo, msg)
    info = linfo
end subroutine frun_mode_jacobian
