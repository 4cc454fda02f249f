!> Contact laws written by the user, evaluated by the solver through a callback.
!>
!> A user law is a C-interoperable function (user_law_fn) that marches one period of its
!> elements in time: relative displacements u at the N samples in, forces f at the same
!> samples out, slider state w updated from the period's start to its end. A run holds
!> one such function and an opaque context pointer (type user_law; frirom_run
!> run_set_user_law); a contact group whose law code is negative (law_user_code) is
!> evaluated here instead of by the built-in AFT, group by group, with the group's index
!> passed to the callback so that one function can serve several laws.
!>
!> The AFT of a user law: harmonics -> samples by the real basis (1, cos, sin, ...); the
!> period is marched again from its closing state until every element's state returns to
!> where the period started (tol relative to the displacement amplitude), as the
!> built-in AFT does; samples -> harmonics by the discrete Fourier sums. The Jacobian is
!> by central differences on the harmonic coefficients: coefficient j of every element
!> moved by +-h_e, h_e = sqrt(eps) max(amplitude of element e, 1e-12 m), each perturbed
!> period closed again from the closed cycle's state (2 ndir (2H+1) closures; O(h^2)
!> where the forces are smooth, O(h) at an event within h of a sample; at a kink the
!> smaller one-sided difference, see column). The same scheme as Python's
!> frirom.laws.aft, so a law gives the same numbers from both.
!>
!> Cost per evaluation: the periods marched times one callback over all the group's
!> elements, plus O(N (2H+1)) per element and direction for the transforms; the Jacobian
!> multiplies this by about 2 ndir (2H+1).
module frirom_user_law
    use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_funptr, c_null_ptr, &
                                           c_null_funptr, c_associated, c_f_procpointer
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_LAW, FRIROM_ERR_NOCLOSE, &
                             FRIROM_ERR_NONFINITE, FRIROM_ERR_SIZE, set_status
    implicit none
    private

    public :: user_law_fn, user_law, user_aft

    abstract interface
        !> One period of ne elements of contact group `group` (1-based): u(ne, ndir, nsamp)
        !> relative displacements (m), params(ne, npar), w(ne, nslider) the state at the
        !> period's start on entry and at its end on return, f(ne, ndir, nsamp) the forces
        !> (N, the sign of the built-in laws). Returns 0, or a nonzero code the run reports
        !> as a law error.
        function user_law_fn(ctx, group, ne, ndir, nsamp, npar, nslider, u, params, w, f) &
            bind(c) result(rc)
            import :: c_int, c_double, c_ptr
            type(c_ptr), value :: ctx
            integer(c_int), value :: group, ne, ndir, nsamp, npar, nslider
            real(c_double), intent(in) :: u(ne, ndir, nsamp), params(ne, npar)
            real(c_double), intent(inout) :: w(ne, nslider)
            real(c_double), intent(out) :: f(ne, ndir, nsamp)
            integer(c_int) :: rc
        end function user_law_fn
    end interface

    !> The callback a run evaluates its user laws with, and its context (owned by the
    !> caller: a Python object, a C struct, a Fortran derived type's c_loc).
    type :: user_law
        type(c_funptr) :: fn = c_null_funptr
        type(c_ptr) :: ctx = c_null_ptr
    end type user_law

contains

    !> Forces f (2H+1, ndir, ne) and optionally the Jacobian jac (ndir(2H+1), ndir(2H+1),
    !> ne) of one user-law group from its displacement harmonics x (2H+1, ndir, ne), at
    !> nsamp samples, starting the march from w0 (nslider, ne); slider: the state with
    !> which the closed cycle starts. The layouts are those of frirom_aft aft_eval.
    subroutine user_aft(ul, group, nsamp, nsl, x, params, w0, f, info, errmsg, jac, slider, &
                        tol, max_periods)
        type(user_law), intent(in) :: ul
        integer(ip), intent(in) :: group, nsamp
        integer(ip), intent(in) :: nsl                  !! slider components per element
        real(wp), intent(in) :: x(:, :, :)          !! (2H+1, ndir, ne), m
        real(wp), intent(in) :: params(:, :)        !! (npar, ne)
        real(wp), intent(in) :: w0(:, :)            !! (>= nslider, ne), m
        real(wp), intent(out) :: f(:, :, :)         !! (2H+1, ndir, ne), N
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        real(wp), intent(out), optional :: jac(:, :, :)
        real(wp), intent(inout), optional :: slider(:, :)  !! (>= nslider, ne)
        real(wp), intent(in), optional :: tol               !! (1e-12)
        integer(ip), intent(in), optional :: max_periods    !! (200)
        procedure(user_law_fn), pointer :: fn
        real(wp), allocatable :: e(:, :), pt(:, :), w(:, :), wc(:, :), ff(:, :, :), &
                                 scale(:), step(:), xp(:, :, :), fp(:, :, :), fm(:, :, :)
        integer(ip) :: nc, nd, ne, npar, j, c, d, k, mp
        real(wp) :: tl, th
        character(len=120) :: buf

        info = FRIROM_OK
        nc = size(x, 1)
        nd = size(x, 2)
        ne = size(x, 3)
        npar = size(params, 1)
        tl = 1.0e-12_wp
        if (present(tol)) tl = tol
        mp = 200
        if (present(max_periods)) mp = max_periods
        if (.not. c_associated(ul%fn)) then
            write (buf, '(a,i0,a)') 'contact group ', group, ': its law is a user law and '// &
                'the run has none (run_set_user_law)'
            call set_status(info, FRIROM_ERR_LAW, errmsg, trim(buf))
            return
        end if
        if (nsamp < nc .or. any(shape(f) /= shape(x)) .or. size(params, 2) /= ne .or. &
            size(w0, 1) < nsl .or. size(w0, 2) /= ne) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'user_aft: nsamp < 2H+1 or '// &
                            'mismatched x, f, params, w0')
            return
        end if
        call c_f_procpointer(ul%fn, fn)
        allocate (e(nsamp, nc))
        do k = 1, nsamp
            th = 2.0_wp*acos(-1.0_wp)*real(k - 1, wp)/real(nsamp, wp)
            e(k, 1) = 1.0_wp
            do c = 1, (nc - 1)/2
                e(k, 2*c) = cos(real(c, wp)*th)
                e(k, 2*c + 1) = sin(real(c, wp)*th)
            end do
        end do
        pt = transpose(params)
        allocate (w(ne, nsl), wc(ne, nsl), ff(ne, nd, nsamp), scale(ne))
        if (nsl > 0) w = transpose(w0(1:nsl, :))
        ! the amplitude of each element's displacement: the closure and step scale
        do j = 1, ne
            scale(j) = max(maxval(abs(matmul(e, x(:, :, j)))), 1.0e-300_wp)
        end do
        call close_cycle(x, w, wc, f)
        if (info /= 0) return
        if (present(slider) .and. nsl > 0) slider(1:nsl, :) = transpose(wc)
        if (.not. present(jac)) return
        allocate (step(ne))
        allocate (xp, mold=x)
        allocate (fp, fm, mold=f)
        step = sqrt(epsilon(1.0_wp))*max(scale, 1.0e-12_wp)
        do d = 1, nd
            do c = 1, nc
                xp = x
                xp(c, d, :) = x(c, d, :) + step
                call close_cycle(xp, wc, w, fp)
                if (info /= 0) return
                xp(c, d, :) = x(c, d, :) - step
                call close_cycle(xp, wc, w, fm)
                if (info /= 0) return
                do j = 1, ne
                    call column(reshape(fp(:, :, j), [nc*nd]), reshape(f(:, :, j), [nc*nd]), &
                                reshape(fm(:, :, j), [nc*nd]), step(j), &
                                jac(:, c + nc*(d - 1), j))
                end do
            end do
        end do

    contains

        !> A Jacobian column from the forces at x + h, x, x - h: the central difference,
        !> or where one side is flat (a one-sided difference below KINK of the other: an
        !> element at its friction limit, stuck on one side and slipping on the other) the
        !> flat side (the slipping side, as the built-in laws' analytical Jacobians take
        !> it), with which Newton converges on the kink instead of halving the error per
        !> iteration. Other kinks (lift-off) keep the central difference, which Newton
        !> follows better from afar.
        pure subroutine column(fplus, f0, fminus, h, jcol)
            real(wp), intent(in) :: fplus(:), f0(:), fminus(:), h
            real(wp), intent(out) :: jcol(:)
            real(wp), parameter :: KINK = 1.0e-3_wp
            real(wp) :: dp(size(f0)), dm(size(f0)), sz
            dp = (fplus - f0)/h
            dm = (f0 - fminus)/h
            sz = max(norm2(dp), norm2(dm))
            if (min(norm2(dp), norm2(dm)) > KINK*sz) then
                jcol = 0.5_wp*(dp + dm)
            else if (norm2(dp) <= norm2(dm)) then
                jcol = dp
            else
                jcol = dm
            end if
        end subroutine column

        !> March periods of xh from the state ws until it closes: fh the harmonics of the
        !> closed period's forces, wout the state entering it.
        subroutine close_cycle(xh, ws, wout, fh)
            real(wp), intent(in) :: xh(:, :, :), ws(:, :)
            real(wp), intent(out) :: wout(:, :), fh(:, :, :)
            real(wp), allocatable :: ut(:, :, :), wn(:, :)
            integer(ip) :: per, ee, dd, rc
            allocate (ut(ne, nd, nsamp))
            do ee = 1, ne
                do dd = 1, nd
                    ut(ee, dd, :) = matmul(e, xh(:, dd, ee))
                end do
            end do
            wout = ws
            wn = ws
            do per = 1, mp
                rc = fn(ul%ctx, int(group, c_int), int(ne, c_int), int(nd, c_int), &
                        int(nsamp, c_int), int(npar, c_int), int(nsl, c_int), ut, pt, wn, ff)
                if (rc /= 0) then
                    write (buf, '(a,i0,a,i0)') 'contact group ', group, &
                        ': the user law returned ', rc
                    call set_status(info, FRIROM_ERR_LAW, errmsg, trim(buf))
                    return
                end if
                if (.not. all(abs(ff) <= huge(1.0_wp))) then
                    write (buf, '(a,i0,a)') 'contact group ', group, &
                        ': the user law returned NaN or Inf forces'
                    call set_status(info, FRIROM_ERR_NONFINITE, errmsg, trim(buf))
                    return
                end if
                if (nsl == 0) exit
                if (all(maxval(abs(wn - wout), dim=2) <= tl*scale)) exit
                if (per == mp) then
                    write (buf, '(a,i0,a,i0,a)') 'contact group ', group, &
                        ': the user law''s state did not close in ', mp, ' periods'
                    call set_status(info, FRIROM_ERR_NOCLOSE, errmsg, trim(buf))
                    return
                end if
                wout = wn
            end do
            ! harmonics: a0 = mean, (a_h, b_h) = 2/N sums against cos, sin
            do ee = 1, ne
                do dd = 1, nd
                    fh(:, dd, ee) = matmul(ff(ee, dd, :), e)*(2.0_wp/real(nsamp, wp))
                    fh(1, dd, ee) = 0.5_wp*fh(1, dd, ee)
                end do
            end do
        end subroutine close_cycle

    end subroutine user_aft

end module frirom_user_law
