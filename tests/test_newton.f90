!> frirom_newton: continuation of the closed-form curve lam = y1^3 - 3 y1, y2 = y1^2 from
!> lam = -4 to lam = 4 through its two turning points (y1 = -1, lam = 2 and y1 = 1,
!> lam = -2), with a dense 2x2 system extending nl_system; and of the corner of the
!> piecewise linear curve y = a (1 - |lam|) (a = 1.5: it turns by 113 degrees at lam = 0,
!> as a contact state switching at one AFT sample can make a harmonic balance curve turn).
!> And a ratchet, y = a lam with the history moved to every converged point, each point a
!> corner (as a contact history carried from point to point makes them); and a ratchet
!> whose curve turns by 91 degrees at lam = c, where the frozen history's branch behind
!> the last point is the only one a corrector across the tangent there meets (the paper
!> flange's ROM_I at F0 = 100 N turned back onto such a branch near its peak).
module newton_test_system
    use frirom_kinds, only: wp, ip
    use frirom_newton, only: nl_system
    implicit none
    type, extends(nl_system) :: cubic_curve
        real(wp) :: j(2, 2) = 0.0_wp
        integer :: nfact = 0
        integer :: neval = 0              !! residual evaluations
        integer :: naccept = 0            !! accepted points (accept hook calls)
        real(wp) :: worst_accept = 0.0_wp !! largest |R| at an accepted point
        real(wp) :: lam_accept = 0.0_wp   !! parameter of the last accepted point
    contains
        procedure :: eval => cc_eval
        procedure :: solve => cc_solve
        procedure :: accept => cc_accept
    end type cubic_curve
    type, extends(nl_system) :: vee_curve
        real(wp) :: a = 1.5_wp
    contains
        procedure :: eval => vee_eval
        procedure :: solve => vee_solve
    end type vee_curve
    !> y = a lam while lam rises past every point made so far, slope b below it: the
    !> accept hook moves the history h to each converged lam, so every point is a corner
    !> whose Jacobian (taken on the side lam <= h, as the AFT's stick Jacobian of a
    !> contact left at the friction limit) gives the slope b, while the curve ahead has
    !> slope a (a ratchet: a contact history carried from point to point).
    !> With c set, the curve ahead turns at lam = c to the slope s2 (s2 = -1.1/3 with a = 3:
    !> 91 degrees, lam still rising): y = a lam up to c, a c + s2 (lam - c) beyond.
    type, extends(vee_curve) :: ratchet_curve
        real(wp) :: b = 0.1_wp, h = -huge(1.0_wp)   !! slope below h (a: vee_curve's)
        real(wp) :: c = huge(1.0_wp), s2 = -1.1_wp/3.0_wp
    contains
        procedure :: eval => ratchet_eval
        procedure :: accept => ratchet_accept
    end type ratchet_curve
    !> R = y - lam + 1e-7 sign(y): no root at lam = 0, R jumps from -1e-7 to 1e-7 at
    !> y = 0 (as forces jump where a contact cycle changes kind): Newton with the slope 1
    !> (vee_curve's solve) and its line search stall at |R| ~1e-7 around the jump.
    type, extends(vee_curve) :: noisy_line
        integer :: neval = 0
    contains
        procedure :: eval => noisy_eval
    end type noisy_line
contains
    subroutine noisy_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(noisy_line), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: r(:), rref, rlam(:)
        logical, intent(in) :: jac
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        this%neval = this%neval + 1
        r(1) = y(1) - lam + merge(1.0e-7_wp, -1.0e-7_wp, y(1) >= 0.0_wp)
        rref = 1.0_wp
        rlam = [-1.0_wp]
        if (jac .and. .false.) errmsg = ''
    end subroutine noisy_eval
    !> The hook must see every converged point once, at the converged (y, lam).
    subroutine cc_accept(this, y, lam, info, errmsg)
        class(cubic_curve), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        this%naccept = this%naccept + 1
        this%lam_accept = lam
        this%worst_accept = max(this%worst_accept, abs(y(1)**3 - 3*y(1) - lam)/max(abs(lam), &
                                1.0_wp))
        if (.false.) errmsg = ''
    end subroutine cc_accept
    subroutine cc_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(cubic_curve), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: r(:), rref, rlam(:)
        logical, intent(in) :: jac
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        this%neval = this%neval + 1
        r(1) = y(1)**3 - 3*y(1) - lam
        r(2) = y(2) - y(1)**2
        rref = max(abs(lam), abs(y(1)**3), 1.0_wp)
        rlam = [-1.0_wp, 0.0_wp]
        if (jac) then
            this%j = reshape([3*y(1)**2 - 3, -2*y(1), 0.0_wp, 1.0_wp], [2, 2])
            this%nfact = this%nfact + 1
        end if
        if (.false.) errmsg = ''
    end subroutine cc_eval
    subroutine cc_solve(this, b, info, errmsg)
        class(cubic_curve), intent(inout) :: this
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        ! lower triangular 2x2
        info = 0
        if (this%j(1, 1) == 0.0_wp) then
            info = 10
            errmsg = 'singular'
            return
        end if
        b(1, :) = b(1, :)/this%j(1, 1)
        b(2, :) = (b(2, :) - this%j(2, 1)*b(1, :))/this%j(2, 2)
    end subroutine cc_solve
    !> R = y - a (1 - |lam|), one unknown: no hyperplane across the tangent before the
    !> corner meets the branch after it (the tangents make 113 degrees).
    subroutine vee_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(vee_curve), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: r(:), rref, rlam(:)
        logical, intent(in) :: jac
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        r(1) = y(1) - this%a*(1.0_wp - abs(lam))
        rref = this%a
        rlam(1) = this%a*sign(1.0_wp, lam)
        if (jac .and. .false.) errmsg = ''
    end subroutine vee_eval
    subroutine vee_solve(this, b, info, errmsg)
        class(vee_curve), intent(inout) :: this
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0      ! dR/dy = 1
        if (.false.) errmsg = ''
        if (.false.) b = b*this%a
    end subroutine vee_solve
    subroutine ratchet_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
        class(ratchet_curve), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        real(wp), intent(out) :: r(:), rref, rlam(:)
        logical, intent(in) :: jac
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        if (lam > this%h) then
            r(1) = y(1) - virgin(lam)
            rlam(1) = -merge(this%a, this%s2, lam <= this%c)
        else
            r(1) = y(1) - virgin(this%h) - this%b*(lam - this%h)
            rlam(1) = -this%b
        end if
        rref = max(abs(y(1)), 1.0_wp)
        if (jac .and. .false.) errmsg = ''
    contains
        !> the curve the ratchet follows while lam rises past its history
        real(wp) function virgin(x)
            real(wp), intent(in) :: x
            virgin = this%a*min(x, this%c) + this%s2*max(x - this%c, 0.0_wp)
        end function virgin
    end subroutine ratchet_eval
    subroutine ratchet_accept(this, y, lam, info, errmsg)
        class(ratchet_curve), intent(inout) :: this
        real(wp), intent(in) :: y(:), lam
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = 0
        this%h = max(this%h, lam)
        if (.false.) errmsg = ''
        if (.false.) info = int(y(1))
    end subroutine ratchet_accept
end module newton_test_system

program test_newton
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done
    use frirom_newton, only: cont_options, newton_correct, cont_tangent, cont_run, &
                             cont_step_factor, chord_wins
    use newton_test_system
    implicit none
    type(cubic_curve) :: s, sq
    type(vee_curve) :: v
    type(ratchet_curve) :: r, rc
    type(noisy_line) :: nz
    logical :: stalled
    type(cont_options) :: o
    real(wp) :: y(2), lam, t(3), ds, yout(2, 500), lout(500), tout(3, 500), y1ref, orient
    integer(ip) :: it(500), npts, info, k, iters, nfold
    logical :: fin, hf
    character(len=256) :: msg
    s%n = 2
    msg = ''
    o%lam_end = 4.0_wp
    o%lscale = 8.0_wp
    o%yscale = 2.0_wp
    o%ds = 0.05_wp
    o%ds_max = 0.05_wp
    o%max_points = 500
    o%tol_r = 1.0e-12_wp
    o%tol_x = 1.0e-10_wp
    ! start on the lower branch at lam = -4 (y1 = -2.1958...)
    y = [-2.0_wp, 4.0_wp]
    lam = -4.0_wp
    hf = .false.
    call newton_correct(s, y, lam, y, lam, [0.0_wp, 0.0_wp], 1.0_wp, o, iters, info, msg, hf)
    call check(info == 0, 'first point: '//trim(msg))
    call check(abs(y(1)**3 - 3*y(1) + 4.0_wp) < 1.0e-11_wp, 'first point on the curve')
    call cont_tangent(s, y, lam, o, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, t, info, msg)
    ds = o%ds
    call cont_run(s, y, lam, t, ds, -4.5_wp, o, yout, lout, tout, it, npts, fin, info, msg, hf)
    call check(info == 0 .and. fin, 'continuation reached lam_end: '//trim(msg))
    call check(s%naccept == npts .and. s%lam_accept == lout(npts), &
               'accept hook called once per point, at the converged point')
    call check(s%worst_accept < 1.0e-9_wp, 'accepted points are on the curve')
    nfold = 0
    do k = 1, npts
        call check(abs(yout(1, k)**3 - 3*yout(1, k) - lout(k)) < 1.0e-9_wp*max(abs(lout(k)), &
                   1.0_wp), 'every point on the curve')
        call check(abs(yout(2, k) - yout(1, k)**2) < 1.0e-9_wp, 'second unknown')
        if (k > 1) then
            if (tout(3, k)*tout(3, k - 1) < 0.0_wp) nfold = nfold + 1
        end if
    end do
    ! the root of y^3 - 3y - 4 = 0 by Cardano
    y1ref = (2.0_wp + sqrt(3.0_wp))**(1.0_wp/3.0_wp) + (2.0_wp - sqrt(3.0_wp))**(1.0_wp/3.0_wp)
    print '(a,i0,a,i0,a,es10.2)', 'points ', npts, ', folds ', nfold, ', |y1_end - ref| ', &
        abs(yout(1, npts) - y1ref)
    call check(nfold == 2, 'two turning points passed')
    call check(lout(npts) == 4.0_wp, 'last point exactly at lam_end')
    call check(abs(yout(1, npts) - y1ref) < 1.0e-10_wp, 'end on the upper branch')
    call check(maxval(lout(1:npts)) < 2.0_wp + 1.0e-9_wp .or. yout(1, npts) > 1.0_wp, &
               'branch order')
    ! with the curve's orientation (sign(det J) t_lam, cont_tangent): the same two folds;
    ! then a step against it (the tangent reversed) retraces the curve and is never taken
    y = [-2.0_wp, 4.0_wp]
    lam = -4.0_wp
    hf = .false.
    call newton_correct(s, y, lam, y, lam, [0.0_wp, 0.0_wp], 1.0_wp, o, iters, info, msg, hf)
    orient = 0.0_wp
    call cont_tangent(s, y, lam, o, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, t, info, msg, orient)
    ! on the lower branch det J = 3 y1^2 - 3 > 0 and lam rises
    call check(info == 0 .and. orient == 1.0_wp, 'orientation at the first point')
    ds = o%ds
    call cont_run(s, y, lam, t, ds, -4.5_wp, o, yout, lout, tout, it, npts, fin, info, msg, &
                  hf, orient=orient)
    nfold = count(tout(3, 2:npts)*tout(3, 1:npts - 1) < 0.0_wp)
    call check(info == 0 .and. fin .and. nfold == 2 .and. &
               abs(yout(1, npts) - y1ref) < 1.0e-10_wp, 'oriented: two folds, upper branch')
    call check(all((3*yout(1, 1:npts)**2 - 3)*tout(3, 1:npts) > 0.0_wp), &
               'oriented: sign(det J) t_lam the same at every point')
    y = yout(:, 10)
    lam = lout(10)
    t = -tout(:, 10)
    ds = 0.05_wp
    o%ds_min = 0.01_wp
    call cont_run(s, y, lam, t, ds, -4.5_wp, o, yout, lout, tout, it, npts, fin, info, msg, &
                  hf, orient=orient)
    ! a tangent against the curve's orientation: refused at every step above ds_min; at
    ! ds_min the caller's direction is taken (the determinant's sign is not trusted there)
    ! and the orientation taken again from it: the run goes back to its end, orient -1
    call check(info == 0 .and. fin .and. orient == -1.0_wp .and. lout(npts) <= -4.5_wp, &
               'a step back along the curve: refused above ds_min, then the caller''s '// &
               'direction, re-oriented: '//trim(msg))
    o%ds_min = 1.0e-6_wp
    ! step factors: each shape measure brought to its target (angle ~ ds, distance ~ ds^2),
    ! the Newton effort limiting, growth and shrink bounded
    call check(abs(cont_step_factor(2.0_wp*o%angle_target, 0.0_wp, 1_ip, o) - 0.5_wp) < &
               1.0e-15_wp, 'twice the target angle halves the step')
    call check(abs(cont_step_factor(0.0_wp, 4.0_wp*o%dist_target, 1_ip, o) - 0.5_wp) < &
               1.0e-15_wp, 'four times the target distance halves the step')
    call check(cont_step_factor(0.0_wp, 0.0_wp, 1_ip, o) == o%grow_max, 'a straight curve grows')
    call check(cont_step_factor(0.0_wp, 0.0_wp, o%iter_target, o) == 1.0_wp, &
               'no growth at the Newton iteration target')
    call check(cont_step_factor(0.0_wp, 0.0_wp, o%iter_target + 3, o) == 0.6_wp, &
               'hard Newton shrinks')
    call check(cont_step_factor(100.0_wp, 100.0_wp, 1_ip, o) == 0.25_wp, 'shrink bounded')
    ! the secant rule (ds = ds_max: the chord wins beyond 60 degrees from J's tangent tj).
    ! tj = (0.3, 0.954) keeps the parameter rising, as the previous tangent (0, 1) did:
    ! a chord 72.6 degrees off it pointing 1e-3 back in lam is corrector noise at a corner
    ! and must not be predicted along (the rule before took it: cos 0.299 < 0.5); the
    ! same chord forward is a corner (taken); 30 degrees off is no corner (not taken);
    ! where tj itself turns the parameter back (a fold), a chord back is taken.
    o%ds_max = 0.05_wp
    call check(.not. chord_wins([1.0_wp, -1.0e-3_wp], [0.3_wp, sqrt(0.91_wp)], &
                                [0.0_wp, 1.0_wp], 0.05_wp, o), &
               'secant: no chord back in lam while J keeps the direction')
    call check(chord_wins([1.0_wp, 1.0e-3_wp], [0.3_wp, sqrt(0.91_wp)], [0.0_wp, 1.0_wp], &
                          0.05_wp, o), 'secant: a forward chord at a corner is taken')
    call check(.not. chord_wins([1.0_wp, sqrt(3.0_wp)], [0.0_wp, 1.0_wp], [0.0_wp, 1.0_wp], &
                                0.05_wp, o), 'secant: no corner within 60 degrees')
    call check(chord_wins([0.0_wp, -1.0_wp], [0.9_wp, -sqrt(0.19_wp)], [0.8_wp, 0.6_wp], &
                          0.05_wp, o), 'secant: a chord back where J turns back too')
    ! a failing corrector at the minimum step stops with a diagnostic, keeping points
    o%max_iter = 1
    o%ds_min = 0.04_wp
    o%tol_r = 1.0e-300_wp
    y = yout(:, 10)
    lam = lout(10)
    t = tout(:, 10)
    ds = 0.05_wp
    call cont_run(s, y, lam, t, ds, -4.5_wp, o, yout, lout, tout, it, npts, fin, info, msg, hf)
    call check(info == 20 .and. npts == 0 .and. index(msg, 'stopped') > 0, &
               'stop diagnostic: '//trim(msg))
    ! the corner of y = a (1 - |lam|), from lam = 1 down to lam = -1
    v%n = 1
    o = cont_options(lam_end=-1.0_wp, ds=0.05_wp, ds_max=0.05_wp, max_points=500, &
                     tol_r=1.0e-12_wp, tol_x=1.0e-10_wp)
    y(1) = 0.0_wp
    lam = 1.0_wp
    call cont_tangent(v, y(1:1), lam, o, [0.0_wp, 0.0_wp], -1.0_wp, t(1:2), info, msg)
    ds = o%ds
    hf = .true.
    call cont_run(v, y(1:1), lam, t(1:2), ds, 1.1_wp, o, yout(1:1, :), lout, tout(1:2, :), &
                  it, npts, fin, info, msg, hf)
    call check(info == 0 .and. fin .and. lout(npts) == -1.0_wp, 'corner turned: '//trim(msg))
    call check(all(abs(yout(1, 1:npts) - v%a*(1.0_wp - abs(lout(1:npts)))) < 1.0e-10_wp), &
               'every point on the V')
    call check(all(lout(2:npts) < lout(1:npts - 1)), 'lam decreases monotonically')
    call check(count(lout(1:npts) < 0.0_wp) > 10 .and. maxval(yout(1, 1:npts)) > 1.4_wp, &
               'the branch beyond the corner followed')
    ! the ratchet: a corner of 66 degrees at every point (slopes 3 and 0.1); following
    ! the tangent J gives (slope b), every step lands 2.5 ds off its predictor and the next
    ! one shrinks (144 points). From y = 0 at lam = 0 to 1.
    call run_ratchet(r, 'ratchet')
    call check(info == 0 .and. fin .and. lout(npts) == 1.0_wp, 'ratchet followed: '//trim(msg))
    call check(all(abs(yout(1, 1:npts) - r%a*lout(1:npts)) < 1.0e-10_wp), &
               'every ratchet point on y = a lam')
    ! steps of ds = 0.05 along (1, a) / |(1, a)|: 0.016 in lam each, about 63, not 500
    call check(npts < 100, 'ratchet: under 100 points (predicting along the chord)')
    ! the ratchet's corner: the tangent J gives at every point (slope b) is replaced by the
    ! chord; past lam = c a corrector across the chord meets nothing within 3 steps, and
    ! the tangent at a predictor past the corner, oriented along the chord, points back
    ! in lam, where it meets the frozen history's branch y = a h + b (lam - h) 114 degrees
    ! from the chord. That point lies against the direction of travel: the run must take
    ! the branch beyond the corner instead and reach lam = 1 (it left through lam_lo).
    rc%c = 0.5_wp
    call run_ratchet(rc, 'ratchet corner')
    call check(info == 0 .and. fin .and. lout(npts) == 1.0_wp, &
               'ratchet corner turned forward: '//trim(msg))
    call check(all(lout(2:npts) > lout(1:npts - 1)), 'ratchet corner: lam rises monotonically')
    call check(abs(yout(1, npts) - (rc%a*rc%c + rc%s2*(1.0_wp - rc%c))) < 1.0e-10_wp, &
               'ratchet corner: the branch beyond the corner followed to lam = 1')
    ! Newton at fixed lam = -4, a fresh J every iteration, the update test deciding (tol_r
    ! loose, as where a large static term sets rref): the 4th update (4.7e-8 < tol_x),
    ! taken once R met tol_r (9.7e-8 < 1e-6), is not followed by an evaluation that could
    ! only confirm it, and each iteration's J comes from the line search's evaluation at
    ! its point (one evaluation per iteration: 4; at first 2 per iteration, 8; then 7),
    ! and the point is on the curve to quadratic convergence's next error (|R| 5e-14;
    ! tolerance 1e-12)
    sq%n = 2
    o = cont_options(tol_r=1.0e-6_wp, tol_x=1.0e-7_wp, reuse_jac=.false.)
    y = [-2.0_wp, 4.0_wp]
    lam = -4.0_wp
    hf = .false.
    call newton_correct(sq, y, lam, y, lam, [0.0_wp, 0.0_wp], 1.0_wp, o, iters, info, msg, hf)
    print '(a,i0,a,i0)', 'fixed-lam Newton: iterations ', iters, ', evaluations ', sq%neval
    call check(info == 0 .and. iters >= 3, 'fixed-lam Newton converged: '//trim(msg))
    call check(sq%neval == iters, 'one evaluation per iteration, none after the last '// &
               'converged update')
    call check(abs(y(1)**3 - 3*y(1) + 4.0_wp) < 1.0e-12_wp .and. &
               abs(y(2) - y(1)**2) < 1.0e-11_wp, 'fixed-lam Newton: on the curve')
    ! a corrector whose residual stalls at its noise (|R| ~1e-7, tol_r 1e-12): with a
    ! stall window of 5 it gives up after 5 iterations without halving its merit, says
    ! so (stalled, the message), and has not used max_iter; without one it takes all 25
    nz%n = 1
    o = cont_options(tol_r=1.0e-12_wp, tol_x=1.0e-12_wp)
    y(1) = 0.3_wp
    lam = 0.0_wp
    hf = .false.
    msg = ''
    call newton_correct(nz, y(1:1), lam, y(1:1), lam, [0.0_wp], 1.0_wp, o, iters, info, msg, &
                        hf, stalled=stalled, stall_window=5_ip)
    print '(a,i0,a,i0,a)', 'noisy line, stall window 5: ', iters, ' iterations, ', &
        nz%neval, ' evaluations'
    call check(info /= 0 .and. stalled .and. iters <= 7 .and. index(msg, '(stalled)') > 0, &
               'a stalled corrector gives up early: '//trim(msg))
    call check(abs(y(1)) < 1.0e-6_wp, 'it stalled at its noise, near the solution')
    y(1) = 0.3_wp
    lam = 0.0_wp
    msg = ''
    call newton_correct(nz, y(1:1), lam, y(1:1), lam, [0.0_wp], 1.0_wp, o, iters, info, msg, &
                        hf, stalled=stalled)
    call check(info /= 0 .and. .not. stalled .and. iters == o%max_iter, &
               'without a window: max_iter iterations ('//trim(msg)//')')
    call check_done('test_newton')
contains
    !> cont_run of a ratchet (slope a = 3) from y = 0 at lam = 0 towards lam = 1, steps of
    !> ds = ds_max = 0.05; the points in yout, lout, tout, it, npts, the end in fin, info, msg.
    subroutine run_ratchet(rr, label)
        class(ratchet_curve), intent(inout) :: rr
        character(len=*), intent(in) :: label
        rr%n = 1
        rr%a = 3.0_wp
        o = cont_options(lam_end=1.0_wp, ds=0.05_wp, ds_max=0.05_wp, max_points=500, &
                         tol_r=1.0e-12_wp, tol_x=1.0e-10_wp)
        y(1) = 0.0_wp
        lam = 0.0_wp
        rr%h = 0.0_wp
        call cont_tangent(rr, y(1:1), lam, o, [0.0_wp, 0.0_wp], 1.0_wp, t(1:2), info, msg)
        ds = o%ds
        hf = .true.
        call cont_run(rr, y(1:1), lam, t(1:2), ds, -0.1_wp, o, yout(1:1, :), lout, &
                      tout(1:2, :), it, npts, fin, info, msg, hf)
        print '(a,i0,a,l1,a,es10.2)', label//': ', npts, ' points, finished ', fin, &
            ', last lam ', lout(max(npts, 1))
    end subroutine run_ratchet
end program test_newton
