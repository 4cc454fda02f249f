!> bind(c) entry points for contact laws written by the user (declared in frirom.h):
!> register a law callback with a run, and the code a user-law contact group carries.
module frirom_capi_laws
    use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_funptr, c_intptr_t, c_associated
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, set_status
    use frirom_aft, only: law_user_code
    use frirom_run, only: run_t, run_from_handle, run_set_user_law
    use frirom_user_law, only: user_law
    use frirom_capi, only: to_c_string
    implicit none
    private
    public :: frirom_run_set_user_law_c, frirom_law_user_code_c

contains

    !> int frirom_run_set_user_law(frirom_run *run, frirom_user_law_fn fn, void *ctx,
    !>                             char *msg, int msglen)
    function frirom_run_set_user_law_c(run, fn, ctx, msg, msglen) result(info) &
        bind(c, name='frirom_run_set_user_law')
        type(c_ptr), value :: run, ctx, msg
        type(c_funptr), value :: fn
        integer(c_int), value :: msglen
        integer(c_int) :: info
        type(run_t), pointer :: r
        integer(ip) :: st
        character(len=512) :: text
        text = ''
        call run_from_handle(transfer(run, 0_c_intptr_t), r, 'frirom_run_set_user_law', st, &
                             text)
        if (st == FRIROM_OK .and. .not. c_associated(fn)) call set_status(st, &
            FRIROM_ERR_PARAM, text, 'frirom_run_set_user_law: fn: NULL')
        if (st == FRIROM_OK) call run_set_user_law(r, user_law(fn, ctx), st, text)
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_user_law_c

    !> int frirom_law_user_code(int ndir, int npar, int nslider): the law code of a
    !> contact group whose law is the run's user law (0: sizes out of range).
    function frirom_law_user_code_c(ndir, npar, nslider) result(code) &
        bind(c, name='frirom_law_user_code')
        integer(c_int), value :: ndir, npar, nslider
        integer(c_int) :: code
        code = int(law_user_code(int(ndir, ip), int(npar, ip), int(nslider, ip)), c_int)
    end function frirom_law_user_code_c

end module frirom_capi_laws
