!> bind(c) entry points for C, C++ and other callers that cannot use Fortran modules.
!> Declared in frirom.h. Arrays are column-major (Fortran order) as documented there;
!> every function returns a frirom status code and writes its message into msg.
module frirom_capi
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_aft
    use frirom_solve, only: frf_settings, frf_result, frf_solve, frf_open, peak_amplitude
    use frirom_run, only: run_t, run_points, run_handle, run_from_handle, run_start, &
                          run_advance, run_solve, run_close, run_set_modes, run_set_selection, &
                          run_checkpoint, run_restore, run_checkpoint_size, RUN_START_COLD, &
                          RUN_SOLVE_FIXED, run_set_free_bodies
    implicit none
    private
    !> The largest frequency a C caller may give (rad/s), as decks (frirom MAX_OMEGA): the
    !> dynamic stiffness K - omega^2 M stays finite.
    real(wp), parameter :: MAX_OMEGA = 1.0e9_wp
    public :: frirom_aft_eval_c, frirom_status_message_c, frirom_settings_default_c, frirom_frf_c
    public :: frirom_run_open_c, frirom_run_sizes_c, frirom_run_set_modes_c, &
              frirom_run_set_selection_c, frirom_run_start_c, frirom_run_advance_c, &
              frirom_run_solve_at_c, frirom_run_checkpoint_c, frirom_run_restore_c, &
              frirom_run_close_c, frirom_run_set_free_bodies_c
    !> for frirom_capi_modes (the nonlinear-mode entry points)
    public :: to_c_string, get_run

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
            if (st /= FRIROM_OK) text = 'frirom_aft_eval: nsamp: '//trim(text)
        end if
        if (st == FRIROM_OK) then
            if (c_associated(jac)) then
                call c_f_pointer(jac, jp, [nd*nc, nd*nc, int(ne, ip)])
                call aft_eval(plan, int(law, ip), xp, pp, wp0, fp, st, text, jac=jp, periods=per)
            else
                call aft_eval(plan, int(law, ip), xp, pp, wp0, fp, st, text, periods=per)
            end if
            if (st /= FRIROM_OK) text = 'frirom_aft_eval (x, params, w0): '//trim(text)
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
        type(frf_settings), intent(out), optional :: s
        if (present(s)) s = frf_settings()
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
        integer(c_int), intent(in), optional :: kr(*), kc(*), mr(*), mc(*), cr(*), cc(*), &
                                                ginfo(*), gr(*), gc(*), outdofs(*)
        real(c_double), intent(in), optional :: kv(*), mv(*), cv(*), zeta(*), gv(*), &
                                                params(*), w0(*), fe(*)
        type(frf_settings), intent(in), optional :: s
        integer(c_int), intent(out), optional :: npts, complete, ny
        real(c_double), intent(out), optional :: omega(*), xo(*), amp(*)
        type(c_ptr), value :: y, msg
        integer(c_int) :: info
        type(frf_result) :: res
        real(c_double), pointer :: yp(:, :)
        integer(ip) :: nc, k, st
        character(len=512) :: text

        text = ''
        st = FRIROM_OK
        if (.not. (present(npts) .and. present(complete) .and. present(ny))) then
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_frf: npts, complete, ny: '// &
                            'NULL (pointers to the results expected)')
            call to_c_string(text, msg, msglen)
            info = int(st, c_int)
            return
        end if
        npts = 0
        complete = 0
        ny = 0
        call check_model('frirom_frf', n, nk, kr, kc, kv, nm, mr, mc, mv, ncd, cr, cc, cv, &
                         alpha, beta, nzeta, zeta, ngroup, ginfo, ng, gr, gc, gv, npar, &
                         params, nw, w0, fe, nout, outdofs, s, st, text)
        if (st == FRIROM_OK) call check_counts('frirom_frf', [maxpts, nycap], &
                                               'maxpts nycap', st, text)
        if (st == FRIROM_OK) call check_range('frirom_frf', omega_start, omega_end, st, text)
        if (st /= FRIROM_OK) then
            continue
        else if (.not. (present(omega) .and. present(xo) .and. present(amp))) then
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_frf: omega, xo, amp: NULL '// &
                            '(room for maxpts points expected)')
        else if (maxpts < s%max_points) then
            call set_status(st, FRIROM_ERR_SIZE, text, 'frirom_frf: maxpts (the room in '// &
                            'omega, xo, amp, y) must be >= settings.max_points')
        end if
        if (st == FRIROM_OK) then
            nc = 2*s%harmonics + 1
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
    !> int frirom_run_open(frirom_run **run, ... as frirom_frf without the range and the
    !> results ..., int sparse, char *msg, int msglen): a run on the model (frirom_solve
    !> frf_open); *run is NULL when it fails.
    function frirom_run_open_c(run, n, nk, kr, kc, kv, nm, mr, mc, mv, ncd, cr, cc, cv, &
                               alpha, beta, nzeta, zeta, ngroup, ginfo, ng, gr, gc, gv, npar, &
                               params, nw, w0, fe, nout, outdofs, s, sparse, msg, msglen) &
        result(info) bind(c, name='frirom_run_open')
        type(c_ptr), intent(out), optional :: run
        integer(c_int), value :: n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout, sparse, &
                                 msglen
        real(c_double), value :: alpha, beta
        integer(c_int), intent(in), optional :: kr(*), kc(*), mr(*), mc(*), cr(*), cc(*), &
                                                ginfo(*), gr(*), gc(*), outdofs(*)
        real(c_double), intent(in), optional :: kv(*), mv(*), cv(*), zeta(*), gv(*), &
                                                params(*), w0(*), fe(*)
        type(frf_settings), intent(in), optional :: s
        type(c_ptr), value :: msg
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st, nc
        character(len=512) :: text
        text = ''
        st = FRIROM_OK
        if (.not. present(run)) then
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_open: run: NULL '// &
                            '(the address of a frirom_run pointer expected)')
            call to_c_string(text, msg, msglen)
            info = int(st, c_int)
            return
        end if
        run = c_null_ptr
        call check_model('frirom_run_open', n, nk, kr, kc, kv, nm, mr, mc, mv, ncd, cr, cc, &
                         cv, alpha, beta, nzeta, zeta, ngroup, ginfo, ng, gr, gc, gv, npar, &
                         params, nw, w0, fe, nout, outdofs, s, st, text)
        if (st == FRIROM_OK) then
            nc = 2*s%harmonics + 1
            allocate (r)
            call frf_open(r, int(n, ip), kr(:nk) + 1, kc(:nk) + 1, kv(:nk), mr(:nm) + 1, &
                          mc(:nm) + 1, mv(:nm), cr(:ncd) + 1, cc(:ncd) + 1, cv(:ncd), alpha, &
                          beta, zeta(:nzeta), reshape(ginfo(:3*ngroup), [3, ngroup]), &
                          gr(:ng) + 1, gc(:ng) + 1, gv(:ng), params(:npar), &
                          reshape(fe(:n*nc), [n, nc]), outdofs(:nout) + 1, s, st, text, &
                          w0=w0(:nw), sparse=sparse /= 0)
            if (st == FRIROM_OK) then
                run = transfer(run_handle(r), run)
            else
                call run_close(r)
                deallocate (r)
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_open_c

    !> int frirom_run_sizes(const frirom_run *run, int *ny, int *nw, int *ne, int *nck)
    function frirom_run_sizes_c(run, ny, nw, ne, nck) result(info) &
        bind(c, name='frirom_run_sizes')
        type(c_ptr), value :: run
        integer(c_int), intent(out), optional :: ny, nw, ne, nck
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        info = FRIROM_ERR_PARAM
        if (.not. (present(ny) .and. present(nw) .and. present(ne) .and. present(nck))) return
        ny = 0
        nw = 0
        ne = 0
        nck = 0
        text = ''
        call get_run(run, 'frirom_run_sizes', r, st, text)
        if (st == FRIROM_OK) then
            ny = int(r%ny, c_int)
            nw = int(r%nw, c_int)
            ne = int(r%netot, c_int)
            nck = int(run_checkpoint_size(r), c_int)
        end if
        info = int(st, c_int)
    end function frirom_run_sizes_c

    !> int frirom_run_set_modes(frirom_run *run, int nmodes, const double *phi,
    !>                          const double *omega, const double *zeta, char *msg, int msglen)
    function frirom_run_set_modes_c(run, nmodes, phi, omega, zeta, msg, msglen) result(info) &
        bind(c, name='frirom_run_set_modes')
        type(c_ptr), value :: run, msg
        integer(c_int), value :: nmodes, msglen
        real(c_double), intent(in), optional :: phi(*), omega(*), zeta(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st, n
        character(len=512) :: text
        call get_run(run, 'frirom_run_set_modes', r, st, text, nmodes, 'nmodes')
        if (st == FRIROM_OK .and. .not. (present(phi) .and. present(omega) .and. &
                                         present(zeta))) call set_status(st, &
            FRIROM_ERR_PARAM, text, 'frirom_run_set_modes: phi, omega, zeta: NULL')
        if (st == FRIROM_OK) then
            n = r%m%ndof
            call run_set_modes(r, reshape(phi(:n*nmodes), [n, int(nmodes, ip)]), &
                               omega(:nmodes), zeta(:nmodes), st, text)
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_modes_c

    !> int frirom_run_set_free_bodies(frirom_run *run, int on, char *msg, int msglen)
    function frirom_run_set_free_bodies_c(run, on, msg, msglen) result(info) &
        bind(c, name='frirom_run_set_free_bodies')
        type(c_ptr), value :: run, msg
        integer(c_int), value :: on, msglen
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        call get_run(run, 'frirom_run_set_free_bodies', r, st, text)
        if (st == FRIROM_OK .and. on /= 0 .and. on /= 1) call set_status(st, &
            FRIROM_ERR_PARAM, text, 'frirom_run_set_free_bodies: on: expected 0 or 1')
        if (st == FRIROM_OK) call run_set_free_bodies(r, on == 1, st, text)
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_free_bodies_c

    !> int frirom_run_set_selection(frirom_run *run, int nnl, const int *keep,
    !>                              const int *pair, int orbits, char *msg, int msglen)
    function frirom_run_set_selection_c(run, nnl, keep, pair, orbits, msg, msglen) &
        result(info) bind(c, name='frirom_run_set_selection')
        type(c_ptr), value :: run, pair, msg
        integer(c_int), value :: nnl, orbits, msglen
        integer(c_int), intent(in), optional :: keep(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(c_int), pointer :: pp(:)
        integer(ip) :: st, h1
        character(len=512) :: text
        call get_run(run, 'frirom_run_set_selection', r, st, text, nnl, 'nnl')
        if (st == FRIROM_OK .and. .not. present(keep)) call set_status(st, FRIROM_ERR_PARAM, &
            text, 'frirom_run_set_selection: keep: NULL')
        if (st == FRIROM_OK) then
            h1 = r%m%nh + 1
            if (c_associated(pair)) then
                call c_f_pointer(pair, pp, [nnl*h1])
                call run_set_selection(r, reshape(int(keep(:nnl*h1), ip), [int(nnl, ip), h1]), &
                                       st, text, pair=reshape(int(pp, ip), [int(nnl, ip), h1]), &
                                       orbits=orbits /= 0)
            else
                call run_set_selection(r, reshape(int(keep(:nnl*h1), ip), [int(nnl, ip), h1]), &
                                       st, text)
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_selection_c

    !> int frirom_run_start(frirom_run *run, double omega_start, double omega_end,
    !>                      char *msg, int msglen): the first point (pending)
    function frirom_run_start_c(run, omega_start, omega_end, msg, msglen) result(info) &
        bind(c, name='frirom_run_start')
        type(c_ptr), value :: run, msg
        real(c_double), value :: omega_start, omega_end
        integer(c_int), value :: msglen
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        text = ''
        call get_run(run, 'frirom_run_start', r, st, text)
        if (st == FRIROM_OK) call check_range('frirom_run_start', omega_start, omega_end, st, &
                                              text)
        if (st == FRIROM_OK) call run_start(r, RUN_START_COLD, omega_start, omega_end, st, text)
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_start_c

    !> int frirom_run_advance(frirom_run *run, int k, int *npts, double *omega, double *xo,
    !>                        double *amp, double *y, int *status, char *msg, int msglen)
    !> Up to k points; omega (k+1), xo (nout, 2H+1, k+1), amp (nout, k+1) and y (ny, k+1)
    !> or NULL have room for k + 1 (the first point comes with the first call).
    function frirom_run_advance_c(run, k, npts, omega, xo, amp, y, status, msg, msglen) &
        result(info) bind(c, name='frirom_run_advance')
        type(c_ptr), value :: run, y, msg
        integer(c_int), value :: k, msglen
        integer(c_int), intent(out), optional :: npts, status
        real(c_double), intent(out), optional :: omega(*), xo(*), amp(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        type(run_points) :: p
        real(c_double), pointer :: yp(:, :)
        integer(ip) :: st, nout, nc, j, o
        character(len=512) :: text
        text = ''
        if (present(npts)) npts = 0
        if (present(status)) status = 0
        call get_run(run, 'frirom_run_advance', r, st, text, k, 'k')
        if (st == FRIROM_OK .and. .not. (present(npts) .and. present(status))) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_advance: npts, status: NULL')
        if (st == FRIROM_OK .and. .not. (present(omega) .and. present(xo) .and. present(amp))) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_advance: omega, xo, amp:'// &
                            ' NULL (room for k + 1 points expected)')
        if (st == FRIROM_OK) call run_advance(r, int(k, ip), p, st, text)
        if (st == FRIROM_OK) then
            nout = r%nout
            nc = 2*r%m%nh + 1
            npts = int(p%npts, c_int)
            status = int(r%status, c_int)
            if (npts > 0) then
                omega(:npts) = p%lam
                xo(:nout*nc*npts) = reshape(p%xo, [nout*nc*npts])
                do j = 1, npts
                    do o = 1, nout
                        amp(o + nout*(j - 1)) = peak_amplitude(p%xo(o, :, j))
                    end do
                end do
                if (c_associated(y)) then
                    call c_f_pointer(y, yp, [r%ny, int(npts, ip)])
                    yp = p%y
                end if
            end if
            text = r%message
            if (r%status == 4) st = r%fail_info
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_advance_c

    !> int frirom_run_solve_at(frirom_run *run, double omega, const double *y0, double *y,
    !>                         double *xo, double *amp, char *msg, int msglen)
    !> One solve at omega from y0 (ny), or from the linear solution when y0 is NULL (with
    !> the homotopy start if Newton fails there); y (ny) or NULL, xo (nout, 2H+1), amp (nout).
    function frirom_run_solve_at_c(run, omega, y0, y, xo, amp, msg, msglen) result(info) &
        bind(c, name='frirom_run_solve_at')
        type(c_ptr), value :: run, y0, y, msg
        real(c_double), value :: omega
        integer(c_int), value :: msglen
        real(c_double), intent(out), optional :: xo(*), amp(*)
        integer(c_int) :: info
        type(run_t), pointer :: r
        type(run_points) :: p
        real(c_double), pointer :: yv(:)
        real(wp), allocatable :: ys(:)
        integer(ip) :: st, nout, nc, o
        character(len=512) :: text
        text = ''
        call get_run(run, 'frirom_run_solve_at', r, st, text)
        if (st == FRIROM_OK .and. .not. (present(xo) .and. present(amp))) call set_status(st, &
            FRIROM_ERR_PARAM, text, 'frirom_run_solve_at: xo, amp: NULL')
        if (st == FRIROM_OK .and. .not. (omega > 0 .and. omega <= MAX_OMEGA)) &
            call set_status(st, FRIROM_ERR_PARAM, text, 'frirom_run_solve_at: omega: a '// &
                            'frequency > 0 and <= 1e9 (rad/s) expected')
        if (st == FRIROM_OK) then
            allocate (ys(r%ny))
            ys = 0.0_wp
            if (c_associated(y0)) then
                call c_f_pointer(y0, yv, [r%ny])
                ys = yv
                if (.not. all(abs(ys) <= huge(1.0_wp))) call set_status(st, &
                    FRIROM_ERR_PARAM, text, 'frirom_run_solve_at: y0: NaN or Inf')
            end if
        end if
        if (st == FRIROM_OK) then
            call run_solve(r, RUN_SOLVE_FIXED, omega, ys, p, st, text, &
                           cold=.not. c_associated(y0))
        end if
        if (st == FRIROM_OK) then
            nout = r%nout
            nc = 2*r%m%nh + 1
            xo(:nout*nc) = reshape(p%xo(:, :, 1), [nout*nc])
            do o = 1, nout
                amp(o) = peak_amplitude(p%xo(o, :, 1))
            end do
            if (c_associated(y)) then
                call c_f_pointer(y, yv, [r%ny])
                yv = p%y(:, 1)
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_solve_at_c

    !> int frirom_run_checkpoint(const frirom_run *run, int nck, double *ck, char *msg,
    !>                           int msglen): nck = frirom_run_sizes' nck
    function frirom_run_checkpoint_c(run, nck, ck, msg, msglen) result(info) &
        bind(c, name='frirom_run_checkpoint')
        type(c_ptr), value :: run, ck, msg
        integer(c_int), value :: nck, msglen
        integer(c_int) :: info
        info = ck_transfer(run, nck, ck, .true., msg, msglen)
    end function frirom_run_checkpoint_c

    !> int frirom_run_restore(frirom_run *run, int nck, const double *ck, char *msg,
    !>                        int msglen): continue from a checkpoint (instead of start)
    function frirom_run_restore_c(run, nck, ck, msg, msglen) result(info) &
        bind(c, name='frirom_run_restore')
        type(c_ptr), value :: run, ck, msg
        integer(c_int), value :: nck, msglen
        integer(c_int) :: info
        info = ck_transfer(run, nck, ck, .false., msg, msglen)
    end function frirom_run_restore_c

    !> Write (save) or read a run's checkpoint of nck doubles at ck.
    function ck_transfer(run, nck, ck, save, msg, msglen) result(info)
        type(c_ptr), intent(in) :: run, ck, msg
        integer(c_int), intent(in) :: nck, msglen
        logical, intent(in) :: save
        integer(c_int) :: info
        type(run_t), pointer :: r
        real(c_double), pointer :: v(:)
        integer(ip) :: st
        character(len=512) :: text
        character(len=*), parameter :: names(2) = ['frirom_run_restore   ', &
                                                   'frirom_run_checkpoint']
        call run_and_ck(run, nck, trim(names(merge(2, 1, save))), r, st, text)
        if (st == FRIROM_OK .and. .not. c_associated(ck)) call set_status(st, &
            FRIROM_ERR_PARAM, text, trim(names(merge(2, 1, save)))//': ck: NULL')
        if (st == FRIROM_OK) then
            call c_f_pointer(ck, v, [nck])
            if (save) then
                call run_checkpoint(r, v, st, text)
            else
                call run_restore(r, v, st, text)
            end if
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function ck_transfer

    !> The run behind a C pointer and a checkpoint length that fits it (FRIROM_ERR_SIZE
    !> naming nck otherwise).
    subroutine run_and_ck(run, nck, who, r, st, text)
        type(c_ptr), intent(in) :: run
        integer(c_int), intent(in) :: nck
        character(len=*), intent(in) :: who
        type(run_t), pointer, intent(out) :: r
        integer(ip), intent(out) :: st
        character(len=*), intent(out) :: text
        text = ''
        call get_run(run, who, r, st, text)
        if (st /= FRIROM_OK) return
        if (nck /= run_checkpoint_size(r)) call set_status(st, FRIROM_ERR_SIZE, text, &
            who//': nck: expected frirom_run_sizes'' nck')
    end subroutine run_and_ck

    !> int frirom_run_close(frirom_run **run): free the run, *run = NULL (NULL: nothing)
    function frirom_run_close_c(run) result(info) bind(c, name='frirom_run_close')
        type(c_ptr), intent(inout), optional :: run
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        info = 0
        if (.not. present(run)) return
        if (.not. c_associated(run)) return
        text = ''
        call get_run(run, 'frirom_run_close', r, st, text)
        if (st == FRIROM_OK) then
            call run_close(r)
            deallocate (r)
        end if
        run = c_null_ptr
        info = int(st, c_int)
    end function frirom_run_close_c

    !> The run behind a C pointer (FRIROM_ERR_PARAM naming `who` for NULL or a closed run)
    !> and, given, a count >= 1 (FRIROM_ERR_SIZE naming it otherwise).
    subroutine get_run(run, who, r, st, text, count, name)
        type(c_ptr), intent(in) :: run
        character(len=*), intent(in) :: who
        type(run_t), pointer, intent(out) :: r
        integer(ip), intent(out) :: st
        character(len=*), intent(inout) :: text
        integer(c_int), intent(in), optional :: count
        character(len=*), intent(in), optional :: name
        text = ''
        call run_from_handle(transfer(run, 0_c_intptr_t), r, who, st, text)
        if (st /= FRIROM_OK .or. .not. present(count)) return
        if (count < 1) call set_status(st, FRIROM_ERR_SIZE, text, who//': '//name// &
                                        ': expected >= 1')
    end subroutine get_run

    !> FRIROM_ERR_SIZE naming the first negative count (names: blank-separated, in order).
    subroutine check_counts(who, counts, names, st, text)
        character(len=*), intent(in) :: who, names
        integer(c_int), intent(in) :: counts(:)
        integer(ip), intent(out) :: st
        character(len=*), intent(inout) :: text
        integer :: k, a, b
        st = FRIROM_OK
        a = 1
        do k = 1, size(counts)
            b = index(names(a:)//' ', ' ') + a - 2
            if (counts(k) < 0) then
                call set_status(st, FRIROM_ERR_SIZE, text, who//': '//names(a:b)// &
                                ': expected a count >= 0')
                return
            end if
            a = b + 2
        end do
    end subroutine check_counts
    !> FRIROM_ERR_PARAM naming omega_start or omega_end unless both are finite, positive
    !> and different.
    subroutine check_range(who, omega_start, omega_end, st, text)
        character(len=*), intent(in) :: who
        real(c_double), intent(in) :: omega_start, omega_end
        integer(ip), intent(inout) :: st
        character(len=*), intent(inout) :: text
        if (.not. (omega_start > 0 .and. omega_start <= MAX_OMEGA)) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': omega_start: finite '// &
                            'positive frequencies (rad/s) up to 1e9 expected')
        else if (.not. (omega_end > 0 .and. omega_end <= MAX_OMEGA &
                        .and. omega_end /= omega_start)) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': omega_end: finite '// &
                            'positive frequencies (rad/s) up to 1e9, other than omega_start,'// &
                            ' expected')
        end if
    end subroutine check_range

    !> The C side of a model's arguments (frirom_frf, frirom_run_open), each failure naming
    !> the argument: settings not NULL, counts >= 0 (n >= 1), no NULL array that a count
    !> asks for, 0-based indices in range, finite values, npar and nw that fit the groups.
    subroutine check_model(who, n, nk, kr, kc, kv, nm, mr, mc, mv, ncd, cr, cc, cv, alpha, &
                           beta, nzeta, zeta, ngroup, ginfo, ng, gr, gc, gv, npar, params, &
                           nw, w0, fe, nout, outdofs, s, st, text)
        character(len=*), intent(in) :: who
        integer(c_int), intent(in) :: n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout
        real(c_double), intent(in) :: alpha, beta
        integer(c_int), intent(in), optional :: kr(*), kc(*), mr(*), mc(*), cr(*), cc(*), &
                                                ginfo(*), gr(*), gc(*), outdofs(*)
        real(c_double), intent(in), optional :: kv(*), mv(*), cv(*), zeta(*), gv(*), &
                                                params(*), w0(*), fe(*)
        type(frf_settings), intent(in), optional :: s
        integer(ip), intent(out) :: st
        character(len=*), intent(inout) :: text
        integer(ip) :: g, nrows, np, nsl, nc
        st = FRIROM_OK
        if (.not. present(s)) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': settings: NULL '// &
                            '(frirom_settings_default fills one)')
            return
        end if
        call check_counts(who, [n, nk, nm, ncd, nzeta, ngroup, ng, npar, nw, nout, &
                                s%harmonics], 'n nk nm ncd nzeta ngroup ng npar nw nout '// &
                          'settings.harmonics', st, text)
        if (st /= FRIROM_OK) return
        nc = 2*s%harmonics + 1
        if (n < 1) then
            call bad('n: expected >= 1 DoF')
        else if (nzeta > n) then
            call bad('nzeta: at most n modal damping ratios expected')
        else if (nk > 0 .and. .not. (present(kr) .and. present(kc) .and. present(kv))) then
            call bad('kr, kc, kv: NULL with nk > 0')
        else if (nm > 0 .and. .not. (present(mr) .and. present(mc) .and. present(mv))) then
            call bad('mr, mc, mv: NULL with nm > 0')
        else if (ncd > 0 .and. .not. (present(cr) .and. present(cc) .and. present(cv))) then
            call bad('cr, cc, cv: NULL with ncd > 0')
        else if (nzeta > 0 .and. .not. present(zeta)) then
            call bad('zeta: NULL with nzeta > 0')
        else if (ngroup > 0 .and. .not. present(ginfo)) then
            call bad('ginfo: NULL with ngroup > 0')
        else if (ng > 0 .and. .not. (present(gr) .and. present(gc) .and. present(gv))) then
            call bad('gr, gc, gv: NULL with ng > 0')
        else if (npar > 0 .and. .not. present(params)) then
            call bad('params: NULL with npar > 0')
        else if (nw > 0 .and. .not. present(w0)) then
            call bad('w0: NULL with nw > 0')
        else if (.not. present(fe)) then
            call bad('fe: NULL (n x (2H+1) excitation harmonics expected)')
        else if (nout > 0 .and. .not. present(outdofs)) then
            call bad('outdofs: NULL with nout > 0')
        end if
        if (st /= FRIROM_OK) return
        if (nk > 0) call triplets('kr', 'kc', 'kv', kr(:nk), kc(:nk), kv(:nk), int(n, ip))
        if (nm > 0 .and. st == FRIROM_OK) &
            call triplets('mr', 'mc', 'mv', mr(:nm), mc(:nm), mv(:nm), int(n, ip))
        if (ncd > 0 .and. st == FRIROM_OK) &
            call triplets('cr', 'cc', 'cv', cr(:ncd), cc(:ncd), cv(:ncd), int(n, ip))
        if (st /= FRIROM_OK) return
        nrows = 0
        np = 0
        nsl = 0
        do g = 1, ngroup
            call law_check(int(ginfo(3*g - 2), ip), st, text, user=.true.)
            if (st /= FRIROM_OK) then
                text = who//': ginfo: '//trim(text)
                return
            end if
            if (ginfo(3*g - 1) < 1 .or. ginfo(3*g) < 1 .or. ginfo(3*g - 1) > huge(1_c_int)/ &
                max(ginfo(3*g), 1_c_int)/8) then
                call bad('ginfo: every group needs >= 1 element and direction')
                return
            end if
            nrows = nrows + int(ginfo(3*g - 1), ip)*ginfo(3*g)
            np = np + law_npar(int(ginfo(3*g - 2), ip))*ginfo(3*g - 1)
            nsl = nsl + law_nslider(int(ginfo(3*g - 2), ip))*ginfo(3*g - 1)
        end do
        if (ng > 0) call triplets('gr', 'gc', 'gv', gr(:ng), gc(:ng), gv(:ng), nrows, &
                                  int(n, ip))
        if (st /= FRIROM_OK) return
        if (npar /= np) then
            call bad('npar: the groups of ginfo need npar = sum of their elements x '// &
                     'the parameters of their law')
        else if (nw > nsl) then
            call bad('nw: more sliders than the groups of ginfo have')
        else if (npar > 0) then
            if (.not. all(abs(params(:npar)) <= huge(1.0_wp))) call bad('params: NaN or Inf')
        end if
        if (st /= FRIROM_OK) return
        call group_params(st)
        if (st /= FRIROM_OK) return
        if (nw > 0) then
            if (.not. all(abs(w0(:nw)) <= huge(1.0_wp))) call bad('w0: NaN or Inf')
        end if
        if (st == FRIROM_OK .and. int(n, ip)*nc < huge(1_c_int)) then
            if (.not. all(abs(fe(:n*nc)) <= huge(1.0_wp))) call bad('fe: NaN or Inf')
        end if
        if (st == FRIROM_OK .and. nout > 0) then
            if (any(outdofs(:nout) < 0 .or. outdofs(:nout) >= n)) &
                call bad('outdofs: 0-based DoFs below n expected')
        end if
    contains
        !> Each group's parameters as its law admits them (frirom_aft's checks, run on
        !> one AFT sample of zero motion per element).
        subroutine group_params(st)
            integer(ip), intent(inout) :: st
            type(aft_plan) :: plan
            integer(ip) :: law, ne, nd, npl, p0
            real(wp), allocatable :: x(:, :, :), f(:, :, :), w(:, :)
            character(len=256) :: why
            call aft_plan_create(plan, 0_ip, 1_ip, st, why)
            p0 = 0
            do g = 1, ngroup
                if (st /= FRIROM_OK) exit
                law = ginfo(3*g - 2)
                ne = ginfo(3*g - 1)
                nd = law_ndir(law)
                npl = law_npar(law)
                if (law < 0) then           ! a user law: its own checks, at evaluation
                    p0 = p0 + npl*ne
                    cycle
                end if
                allocate (x(1, nd, ne), f(1, nd, ne), w(max(law_nslider(law), 1_ip), ne))
                x = 0.0_wp
                w = 0.0_wp
                why = ''
                call aft_eval(plan, law, x, reshape(params(p0 + 1:p0 + npl*ne), [npl, ne]), &
                              w, f, st, why)
                if (st /= FRIROM_OK) text = who//': params of contact group '// &
                                            trim(itoa(g))//': '//trim(why)
                p0 = p0 + npl*ne
                deallocate (x, f, w)
            end do
            call aft_plan_destroy(plan)
        end subroutine group_params

        subroutine bad(what)
            character(len=*), intent(in) :: what
            call set_status(st, FRIROM_ERR_PARAM, text, who//': '//what)
        end subroutine bad

        subroutine triplets(rn, cn, vn, r, c, v, nr, ncol)
            character(len=*), intent(in) :: rn, cn, vn
            integer(c_int), intent(in) :: r(:), c(:)
            real(c_double), intent(in) :: v(:)
            integer(ip), intent(in) :: nr
            integer(ip), intent(in), optional :: ncol
            integer(ip) :: nco
            nco = nr
            if (present(ncol)) nco = ncol
            if (any(r < 0 .or. r >= nr)) then
                call bad(rn//': a row index outside 0..'//trim(itoa(nr - 1)))
            else if (any(c < 0 .or. c >= nco)) then
                call bad(cn//': a column index outside 0..'//trim(itoa(nco - 1)))
            else if (.not. all(abs(v) <= huge(1.0_wp))) then
                call bad(vn//': NaN or Inf')
            end if
        end subroutine triplets
    end subroutine check_model

end module frirom_capi
