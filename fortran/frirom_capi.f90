!> bind(c) entry points for C, C++ and other callers that cannot use Fortran modules.
!> Declared in frirom.h. Arrays are column-major (Fortran order) as documented there;
!> every function returns a frirom status code and writes its message into msg.
module frirom_capi
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_aft
    use frirom_solve, only: frf_settings, frf_result, frf_solve
    implicit none
    private
    public :: frirom_aft_eval_c, frirom_status_message_c, frirom_settings_default_c, frirom_frf_c

contains

    !> Copy a Fortran string into a NUL-terminated C buffer of msglen bytes.
    subroutine to_c_string(text, msg, msglen)
        character(len=*), intent(in) :: text
        type(c_ptr), intent(in) :: msg
        integer(c_int), intent(in) :: msglen
        character(kind=c_char), pointer :: buf(:)
        integer :: i, n
        if (.not. c_associated(msg) .or. msglen <= 0) return
        call c_f_pointer(msg, buf, [msglen])
        n = min(len_trim(text), msglen - 1)
        do i = 1, n
            buf(i) = text(i:i)
        end do
        buf(n + 1) = c_null_char
    end subroutine to_c_string

    !> int frirom_status_message(int info, char *msg, int msglen)
    function frirom_status_message_c(info, msg, msglen) result(res) &
        bind(c, name='frirom_status_message')
        integer(c_int), value :: info, msglen
        type(c_ptr), value :: msg
        integer(c_int) :: res
        call to_c_string(frirom_status_message(int(info, ip)), msg, msglen)
        res = 0
    end function frirom_status_message_c

    !> int frirom_aft_eval(int law, int nharm, int nsamp, int ne, const double *x,
    !>                     const double *params, const double *w0, double *f, double *jac,
    !>                     int *periods, char *msg, int msglen)
    !> x, f: (2H+1, ndir, ne); params: (npar, ne); w0: (nslider, ne) or NULL for zeros;
    !> jac: (ndir(2H+1), ndir(2H+1), ne) or NULL; periods: (ne) or NULL.
    function frirom_aft_eval_c(law, nharm, nsamp, ne, x, params, w0, f, jac, periods, msg, &
                               msglen) result(info) bind(c, name='frirom_aft_eval')
        integer(c_int), value :: law, nharm, nsamp, ne, msglen
        type(c_ptr), value :: x, params, w0, f, jac, periods, msg
        integer(c_int) :: info
        type(aft_plan) :: plan
        real(wp), pointer :: xp(:, :, :), pp(:, :), wp0(:, :), fp(:, :, :), jp(:, :, :)
        real(wp), allocatable, target :: wzero(:, :)
        integer(c_int), pointer :: perp(:)
        integer(ip) :: st, nd, nc, ns, per(max(ne, 0))
        character(len=512) :: text

        text = ''
        nd = law_ndir(int(law, ip))
        nc = 2*nharm + 1
        ! an unknown law is reported with the codes and names of frirom_aft's law table
        call law_check(int(law, ip), st, text)
        if (st == FRIROM_OK) then
            if (ne < 0 .or. nharm < 0) then
                call set_status(st, FRIROM_ERR_PARAM, text, 'ne and nharm must be >= 0')
            else if (.not. (c_associated(x) .and. c_associated(params) &
                            .and. c_associated(f))) then
                call set_status(st, FRIROM_ERR_PARAM, text, 'x, params and f must not be NULL')
            end if
        end if
        if (st == FRIROM_OK) then
            ns = max(law_nslider(int(law, ip)), 1_ip)
            call c_f_pointer(x, xp, [nc, nd, int(ne, ip)])
            call c_f_pointer(params, pp, [law_npar(int(law, ip)), int(ne, ip)])
            call c_f_pointer(f, fp, [nc, nd, int(ne, ip)])
            if (c_associated(w0)) then
                call c_f_pointer(w0, wp0, [ns, int(ne, ip)])
            else
                allocate (wzero(ns, ne))
                wzero = 0.0_wp
                wp0 => wzero
            end if
            call aft_plan_create(plan, int(nharm, ip), int(nsamp, ip), st, text)
        end if
        if (st == FRIROM_OK) then
            if (c_associated(jac)) then
                call c_f_pointer(jac, jp, [nd*nc, nd*nc, int(ne, ip)])
                call aft_eval(plan, int(law, ip), xp, pp, wp0, fp, st, text, jac=jp, periods=per)
            else
                call aft_eval(plan, int(law, ip), xp, pp, wp0, fp, st, text, periods=per)
            end if
            if (c_associated(periods)) then
                call c_f_pointer(periods, perp, [ne])
                perp = int(per, c_int)
            end if
        end if
        call aft_plan_destroy(plan)
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_aft_eval_c

    !> void frirom_settings_default(struct frirom_settings *s)
    subroutine frirom_settings_default_c(s) bind(c, name='frirom_settings_default')
        type(frf_settings), intent(out) :: s
        s = frf_settings()
    end subroutine frirom_settings_default_c

    !> int frirom_frf(...): the whole forced-response solve of frirom_solve frf_solve for C
    !> (see frirom.h); indices 0-based, arrays column-major, results in caller memory.
    function frirom_frf_c(n, nk, kr, kc, kv, nm, mr, mc, mv, ncd, cr, cc, cv, alpha, beta, &
                          nzeta, zeta, ngroup, ginfo, ng, gr, gc, gv, npar, params, nw, w0, &
                          fe, omega_start, omega_end, nout, outdofs, s, maxpts, npts, &
                          complete, omega, xo, amp, nycap, ny, y, msg, msglen) result(info) &
        bind(c, name='frirom_frf')
        integer(c_int), value :: n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout, maxpts, &
                                 nycap, msglen
        real(c_double), value :: alpha, beta, omega_start, omega_end
        integer(c_int), intent(in) :: kr(*), kc(*), mr(*), mc(*), cr(*), cc(*), ginfo(*), &
                                      gr(*), gc(*), outdofs(*)
        real(c_double), intent(in) :: kv(*), mv(*), cv(*), zeta(*), gv(*), params(*), w0(*), &
                                      fe(*)
        type(frf_settings), intent(in) :: s
        integer(c_int), intent(out) :: npts, complete, ny
        real(c_double), intent(out) :: omega(*), xo(*), amp(*)
        type(c_ptr), value :: y, msg
        integer(c_int) :: info
        type(frf_result) :: res
        real(c_double), pointer :: yp(:, :)
        integer(ip) :: nc, k, st
        character(len=512) :: text

        npts = 0
        complete = 0
        ny = 0
        nc = 2*s%harmonics + 1
        text = ''
        st = FRIROM_OK
        if (min(n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout, maxpts, nycap) < 0 .or. &
            s%harmonics < 0) then
            call set_status(st, FRIROM_ERR_SIZE, text, 'frirom_frf: negative count')
        else if (maxpts < s%max_points) then
            call set_status(st, FRIROM_ERR_SIZE, text, 'frirom_frf: maxpts (the room in '// &
                            'omega, xo, amp, y) must be >= settings.max_points')
        end if
        if (st == FRIROM_OK) then
            if (nw > 0) then
                call frf_solve(n, kr(:nk) + 1, kc(:nk) + 1, kv(:nk), mr(:nm) + 1, mc(:nm) + 1, &
                               mv(:nm), cr(:ncd) + 1, cc(:ncd) + 1, cv(:ncd), alpha, beta, &
                               zeta(:nzeta), reshape(ginfo(:3*ngroup), [3, ngroup]), &
                               gr(:ng) + 1, gc(:ng) + 1, gv(:ng), params(:npar), &
                               reshape(fe(:n*nc), [n, nc]), omega_start, omega_end, &
                               outdofs(:nout) + 1, s, res, w0=w0(:nw))
            else
                call frf_solve(n, kr(:nk) + 1, kc(:nk) + 1, kv(:nk), mr(:nm) + 1, mc(:nm) + 1, &
                               mv(:nm), cr(:ncd) + 1, cc(:ncd) + 1, cv(:ncd), alpha, beta, &
                               zeta(:nzeta), reshape(ginfo(:3*ngroup), [3, ngroup]), &
                               gr(:ng) + 1, gc(:ng) + 1, gv(:ng), params(:npar), &
                               reshape(fe(:n*nc), [n, nc]), omega_start, omega_end, &
                               outdofs(:nout) + 1, s, res)
            end if
            st = res%info
            text = res%message
            npts = res%npts
            complete = merge(1, 0, res%complete)
            ny = res%ny
            omega(:npts) = res%omega
            xo(:nout*nc*npts) = reshape(res%xo, [nout*nc*npts])
            amp(:nout*npts) = reshape(res%amp, [nout*npts])
            if (c_associated(y)) then
                if (nycap < res%ny) then
                    if (st == FRIROM_OK) call set_status(st, FRIROM_ERR_SIZE, text, &
                                                         'frirom_frf: nycap < ny, y not filled')
                else
                    call c_f_pointer(y, yp, [int(nycap, ip), int(maxpts, ip)])
                    do k = 1, npts
                        yp(:res%ny, k) = res%y(:, k)
                    end do
                end if
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_frf_c
end module frirom_capi
