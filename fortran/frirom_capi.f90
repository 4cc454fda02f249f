!> bind(c) entry points for C, C++ and other callers that cannot use Fortran modules.
!> Declared in frirom.h. Arrays are column-major (Fortran order) as documented there;
!> every function returns a frirom status code and writes its message into msg.
module frirom_capi
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_aft
    implicit none
    private
    public :: frirom_aft_eval_c, frirom_status_message_c

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
end module frirom_capi
