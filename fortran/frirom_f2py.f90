! The only source f2py reads. Plain subroutines with explicit-shape arrays and real(8) /
! integer(4) dummies (f2py would map a real(wp) from another module to C float). Each one
! unpacks its arguments, calls the library and returns `info` plus the library's message.
! Derived types never cross this file.

!> Text of a frirom status code.
subroutine status_message(info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: frirom_status_message
    implicit none
    integer(4), intent(in) :: info
    character(len=512), intent(out) :: msg
    msg = frirom_status_message(int(info, ip))
end subroutine status_message

! ---- contact laws and AFT ----------------------------------------------------------

!> AFT forces (and Jacobian when nje = ne) of ne elements of one law; see frirom_aft.
!> Shapes: x, f (2H+1, ndir, ne); params (npar, ne); w0 (nsl, ne) with nsl >= 1;
!> jac (nj, nj, nje) with nj = ndir(2H+1) and nje = ne, or nje = 0 for no Jacobian.
subroutine aft_eval(law, nharm, nsamp, ndir, npar, nsl, ne, nj, nje, x, params, w0, tol, &
                    max_periods, f, jac, periods, states, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_aft, only: aft_plan, aft_plan_create, aft_plan_destroy, &
                          frirom_aft_eval => aft_eval
    implicit none
    integer(4), intent(in) :: law, nharm, nsamp, ndir, npar, nsl, ne, nj, nje, max_periods
    real(8), intent(in) :: x(2*nharm + 1, ndir, ne), params(npar, ne), w0(nsl, ne), tol
    real(8), intent(out) :: f(2*nharm + 1, ndir, ne), jac(nj, nj, nje)
    integer(4), intent(out) :: periods(ne)
    real(8), intent(out) :: states(3, ne)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(aft_plan) :: plan
    integer(ip) :: st, per(ne)
    msg = ''
    f = 0.0d0
    periods = 0
    states = 0.0d0
    call aft_plan_create(plan, int(nharm, ip), int(nsamp, ip), st, msg)
    if (st == 0) then
        if (nje > 0) then
            call frirom_aft_eval(plan, int(law, ip), x, params, w0, f, st, msg, jac=jac, &
                                 periods=per, states=states, tol=real(tol, wp), &
                                 max_periods=int(max_periods, ip), index_base=0_ip)
        else
            call frirom_aft_eval(plan, int(law, ip), x, params, w0, f, st, msg, periods=per, &
                                 states=states, tol=real(tol, wp), &
                                 max_periods=int(max_periods, ip), index_base=0_ip)
        end if
        periods = per
    end if
    call aft_plan_destroy(plan)
    info = st
end subroutine aft_eval

!> Time histories of the closed cycle: xt, ft (nsamp, ndir, ne); see frirom_aft.
subroutine aft_time(law, nharm, nsamp, ndir, npar, nsl, ne, x, params, w0, tol, max_periods, &
                    xt, ft, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_aft, only: aft_plan, aft_plan_create, aft_plan_destroy, &
                          frirom_aft_time => aft_time
    implicit none
    integer(4), intent(in) :: law, nharm, nsamp, ndir, npar, nsl, ne, max_periods
    real(8), intent(in) :: x(2*nharm + 1, ndir, ne), params(npar, ne), w0(nsl, ne), tol
    real(8), intent(out) :: xt(nsamp, ndir, ne), ft(nsamp, ndir, ne)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(aft_plan) :: plan
    integer(ip) :: st
    msg = ''
    xt = 0.0d0
    ft = 0.0d0
    call aft_plan_create(plan, int(nharm, ip), int(nsamp, ip), st, msg)
    if (st == 0) call frirom_aft_time(plan, int(law, ip), x, params, w0, xt, ft, st, msg, &
                                      tol=real(tol, wp), max_periods=int(max_periods, ip), &
                                      index_base=0_ip)
    call aft_plan_destroy(plan)
    info = st
end subroutine aft_time

! ---- harmonic balance solver -------------------------------------------------------

! ---- reduction: eigen-solves, Craig-Bampton, interface reduction -------------------
