!> frirom_user_law from Fortran, as a legacy code plugs in its own law: the Jenkins law
!> written here as a bind(c) user_law_fn gives the built-in Jenkins AFT's forces to
!> 1e-10 and its Jacobian to 1e-6 (differences against the analytical one) for elements
!> in stick, partial slip and gross slip, with the slider of the closed cycle; the
!> context comes back untouched; a missing callback and a failing law return status codes
!> with messages.
module test_user_law_laws
    use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
    implicit none
contains
    function jenkins(ctx, group, ne, ndir, nsamp, npar, nslider, u, params, w, f) &
        bind(c) result(rc)
        type(c_ptr), value :: ctx
        integer(c_int), value :: group, ne, ndir, nsamp, npar, nslider
        real(c_double), intent(in) :: u(ne, ndir, nsamp), params(ne, npar)
        real(c_double), intent(inout) :: w(ne, nslider)
        real(c_double), intent(out) :: f(ne, ndir, nsamp)
        integer(c_int) :: rc
        integer(c_int), pointer :: calls
        real(c_double) :: t, lim
        integer :: e, k
        call c_f_pointer(ctx, calls)
        calls = calls + 1
        rc = 0
        f = 0.0_c_double
        if (group /= 2 .or. calls > 100000) then
            rc = 3
            return
        end if
        do k = 1, nsamp
            do e = 1, ne
                lim = params(e, 2)*max(params(e, 3), 0.0_c_double)
                t = params(e, 1)*(u(e, 1, k) - w(e, 1))
                if (abs(t) > lim) then
                    t = sign(lim, t)
                    w(e, 1) = u(e, 1, k) - t/params(e, 1)
                end if
                f(e, 1, k) = t
            end do
        end do
    end function jenkins
end module test_user_law_laws

program test_user_law
    use, intrinsic :: iso_c_binding, only: c_funloc, c_loc, c_int
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_aft
    use frirom_user_law, only: user_law, user_aft
    use frirom_check, only: check, check_done
    use test_user_law_laws, only: jenkins
    implicit none
    integer(ip), parameter :: nh = 3, nc = 2*nh + 1, ns = 256, ne = 3
    type(aft_plan) :: plan
    type(user_law) :: ul
    integer(c_int), target :: calls
    integer(ip) :: info
    real(wp) :: x(nc, 1, ne), p(3, ne), w0(1, ne), f(nc, 1, ne), g(nc, 1, ne)
    real(wp) :: ja(nc, nc, ne), ju(nc, nc, ne), sa(1, ne), su(1, ne)
    character(len=300) :: msg

    call aft_plan_create(plan, nh, ns, info, msg)
    call check(info == FRIROM_OK, 'plan')
    x = 0.0_wp
    x(2, 1, :) = [1.0e-4_wp, 6.0e-4_wp, 5.0e-3_wp]     ! stick, partial slip, gross slip
    x(3, 1, :) = [0.5e-4_wp, -2.0e-4_wp, 1.0e-3_wp]
    x(4, 1, :) = [0.0_wp, 1.0e-4_wp, -1.0e-3_wp]
    x(1, 1, :) = [1.0e-5_wp, 0.0_wp, 2.0e-4_wp]
    p = spread([1.0e5_wp, 0.3_wp, 100.0_wp], 2, ne)
    w0 = 0.0_wp
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg, jac=ja, slider=sa)
    call check(info == FRIROM_OK, 'built-in jenkins')

    calls = 0
    msg = ''
    call user_aft(ul, 2_ip, ns, 1_ip, x, p, w0, g, info, msg)
    call check(info == FRIROM_ERR_LAW .and. index(msg, 'run_set_user_law') > 0, &
               'no callback: '//trim(msg))
    ul = user_law(c_funloc(jenkins), c_loc(calls))
    call user_aft(ul, 2_ip, ns, 1_ip, x, p, w0, g, info, msg, jac=ju, slider=su)
    call check(info == FRIROM_OK, 'user jenkins: '//trim(msg))
    call check(calls > 0, 'the context came back')
    call check(maxval(abs(f - g)) <= 1.0e-10_wp*maxval(abs(f)), 'forces')
    call check(maxval(abs(ja - ju)) <= 1.0e-6_wp*maxval(abs(ja)), 'jacobian')
    call check(maxval(abs(sa - su)) <= 1.0e-12_wp*maxval(abs(x)), 'slider')
    msg = ''
    call user_aft(ul, 1_ip, ns, 1_ip, x, p, w0, g, info, msg)
    call check(info == FRIROM_ERR_LAW .and. index(msg, 'returned 3') > 0, &
               'failing law: '//trim(msg))
    call aft_plan_destroy(plan)
    call check_done('test_user_law')
end program test_user_law
