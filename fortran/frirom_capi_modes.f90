!> Nonlinear modes (EPMC) through the C interface (frirom.h): an open run becomes a mode
!> run (frirom_run run_to_mode, run_set_nonlinear_mode), starts from its linear mode and
!> gives amplitude, frequency, artificial damping and output harmonics per point.
module frirom_capi_modes
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, set_status
    use frirom_run, only: run_t, run_points, run_to_mode, run_set_nonlinear_mode, run_start, &
                          run_advance, RUN_MODE, RUN_START_COLD, RUN_FAILED
    use frirom_capi, only: to_c_string, get_run
    implicit none
    private
    public :: frirom_run_set_nonlinear_mode_c, frirom_run_start_mode_c, &
              frirom_run_advance_mode_c

contains

    !> int frirom_run_set_nonlinear_mode(frirom_run *run, const double *phi, double omega0,
    !>                                   int nmodes, const double *modes,
    !>                                   const double *omega, const double *zeta,
    !>                                   char *msg, int msglen)
    function frirom_run_set_nonlinear_mode_c(run, phi, omega0, nmodes, modes, omega, zeta, &
                                             msg, msglen) result(info) &
        bind(c, name='frirom_run_set_nonlinear_mode')
        type(c_ptr), value :: run, msg
        real(c_double), value :: omega0
        integer(c_int), value :: nmodes, msglen
        real(c_double), intent(in), optional :: phi(*), modes(*), omega(*), zeta(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st, n
        character(len=512) :: text
        call get_run(run, 'frirom_run_set_nonlinear_mode', r, st, text)
        if (st == FRIROM_OK .and. .not. present(phi)) call set_status(st, FRIROM_ERR_PARAM, &
            text, 'frirom_run_set_nonlinear_mode: phi: NULL')
        if (st == FRIROM_OK .and. nmodes < 0) call set_status(st, FRIROM_ERR_SIZE, text, &
            'frirom_run_set_nonlinear_mode: nmodes: expected >= 0')
        if (st == FRIROM_OK .and. nmodes > 0 .and. .not. (present(modes) .and. &
                                                         present(omega) .and. present(zeta))) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_set_nonlinear_mode: '// &
                            'modes, omega, zeta: NULL with nmodes > 0')
        if (st == FRIROM_OK) call run_to_mode(r, nmodes > 0, st, text)
        if (st == FRIROM_OK) then
            n = r%m%ndof
            if (nmodes > 0) then
                call run_set_nonlinear_mode(r, phi(:n), omega0, st, text, &
                                            modes=reshape(modes(:n*nmodes), &
                                                          [n, int(nmodes, ip)]), &
                                            wm=omega(:nmodes), zm=zeta(:nmodes))
            else
                call run_set_nonlinear_mode(r, phi(:n), omega0, st, text)
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_nonlinear_mode_c

    !> int frirom_run_start_mode(frirom_run *run, double a_start, double a_end, char *msg,
    !>                           int msglen)
    function frirom_run_start_mode_c(run, a_start, a_end, msg, msglen) result(info) &
        bind(c, name='frirom_run_start_mode')
        type(c_ptr), value :: run, msg
        real(c_double), value :: a_start, a_end
        integer(c_int), value :: msglen
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        call get_run(run, 'frirom_run_start_mode', r, st, text)
        if (st == FRIROM_OK .and. r%m%mode /= RUN_MODE) call set_status(st, FRIROM_ERR_PARAM, &
            text, 'frirom_run_start_mode: not a mode run (frirom_run_set_nonlinear_mode)')
        if (st == FRIROM_OK .and. .not. (a_start > 0.0_wp .and. a_end > 0.0_wp .and. &
                                         a_start <= huge(1.0_wp) .and. &
                                         a_end <= huge(1.0_wp) .and. a_start /= a_end)) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_start_mode: a_start, '// &
                            'a_end: different positive finite modal amplitudes expected')
        if (st == FRIROM_OK) call run_start(r, RUN_START_COLD, log10(a_start), log10(a_end), &
                                            st, text)
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_start_mode_c

    !> int frirom_run_advance_mode(frirom_run *run, int k, int *npts, double *amplitude,
    !>                             double *omega, double *xi, double *xo, int *status,
    !>                             char *msg, int msglen)
    function frirom_run_advance_mode_c(run, k, npts, amplitude, omega, xi, xo, status, msg, &
                                       msglen) result(info) bind(c, name='frirom_run_advance_mode')
        type(c_ptr), value :: run, msg
        integer(c_int), value :: k, msglen
        integer(c_int), intent(out), optional :: npts, status
        real(c_double), intent(out), optional :: amplitude(*), omega(*), xi(*), xo(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        type(run_points) :: p
        integer(ip) :: st, nout, nc, j, ny
        real(wp) :: w0
        character(len=512) :: text
        if (present(npts)) npts = 0
        if (present(status)) status = 0
        call get_run(run, 'frirom_run_advance_mode', r, st, text, k, 'k')
        if (st == FRIROM_OK .and. .not. (present(npts) .and. present(status) .and. &
                                         present(amplitude) .and. present(omega) .and. &
                                         present(xi) .and. present(xo))) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_advance_mode: npts, '// &
                            'amplitude, omega, xi, xo, status: NULL (room for k + 1 points)')
        if (st == FRIROM_OK .and. r%m%mode /= RUN_MODE) call set_status(st, FRIROM_ERR_PARAM, &
            text, 'frirom_run_advance_mode: not a mode run')
        if (st == FRIROM_OK) call run_advance(r, int(k, ip), p, st, text)
        if (st == FRIROM_OK) then
            nout = r%nout
            nc = 2*r%m%nh + 1
            ny = r%ny
            w0 = r%m%mode_w0
            npts = int(p%npts, c_int)
            status = int(r%status, c_int)
            do j = 1, p%npts
                amplitude(j) = 10.0_wp**p%lam(j)
                omega(j) = w0*p%y(ny - 1, j)
                xi(j) = w0*p%y(ny, j)
            end do
            if (p%npts > 0) xo(:nout*nc*p%npts) = reshape(p%xo, [nout*nc*p%npts])
            text = r%message
            if (r%status == RUN_FAILED) st = r%fail_info
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_advance_mode_c
end module frirom_capi_modes
