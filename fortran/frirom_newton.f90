!> Newton's method with the analytical Jacobian and pseudo-arc-length continuation on an
!> abstract nonlinear system R(y, lam) = 0 (lam: frequency or load parameter).
!>
!> The system (an extension of nl_system) evaluates R, factorises dR/dy and gives dR/dlam;
!> this module owns the iteration: bordered Newton corrector with backtracking, residual
!> and update tests that are relative (the same in N and mN), Jacobian reuse while the
!> iteration contracts fast, tangent predictor, steps adapted to the curve's shape (angle
!> between successive tangents, predictor-corrector distance) and limited by the Newton
!> effort, turning points, retries.
module frirom_newton
    use frirom_kinds, only: wp, ip
    use frirom_lapack, only: dgetrf
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_NOCONV, FRIROM_ERR_NONFINITE, FRIROM_ERR_CONT, &
                             set_status
    implicit none
    private
    public :: nl_system, cont_options, newton_correct, cont_tangent, cont_run, cont_step_factor
    public :: chord_wins
    public :: cont_options_from, YSCALE_RELATIVE
    public :: RCONT_TOL_R, RCONT_TOL_X, RCONT_TOL_STALL, RCONT_YSCALE, RCONT_LSCALE, &
              RCONT_DS, RCONT_DS_MIN, RCONT_DS_MAX, RCONT_LAM_END, RCONT_LAM_LO, N_RCONT
    public :: ICONT_MAX_ITER, ICONT_REUSE_JAC, N_ICONT

    !> Slots of the continuation settings as one real and one integer array, for callers
    !> that cannot pass a cont_options across their boundary (frirom_f2py, C): the fields
    !> of the same names, and RCONT_LAM_LO, the lower parameter bound cont_run takes.
    integer(ip), parameter :: RCONT_TOL_R = 1, RCONT_TOL_X = 2, RCONT_TOL_STALL = 3, &
                              RCONT_YSCALE = 4, RCONT_LSCALE = 5, RCONT_DS = 6, &
                              RCONT_DS_MIN = 7, RCONT_DS_MAX = 8, RCONT_LAM_END = 9, &
                              RCONT_LAM_LO = 10, N_RCONT = 10
    integer(ip), parameter :: ICONT_MAX_ITER = 1, ICONT_REUSE_JAC = 2, N_ICONT = 2
    !> yscale of a solve before any solution size is known: the update test becomes purely
    !> relative, ||dy|| / ||y|| (arc lengths in this scaling mean nothing)
    real(wp), parameter :: YSCALE_RELATIVE = 1.0e-300_wp
    !> Systems of at most this many unknowns orient their tangents by the sign of det J
    !> (jac_det_sign: J^-1 formed by n solves, then an LU): a few hundred microseconds
    integer(ip), parameter :: DET_MAX_N = 64

    !> A nonlinear system R(y, lam) = 0 with n unknowns y and one parameter lam.
    type, abstract :: nl_system
        integer(ip) :: n = 0       !! number of unknowns y
    contains
        procedure(eval_iface), deferred :: eval
        procedure(solve_iface), deferred :: solve
        procedure :: accept => nl_accept
        procedure :: roundoff => nl_roundoff
        procedure :: begin_correct => nl_begin_correct
        procedure :: settled => nl_settled
    end type nl_system

    abstract interface
        !> Residual r = R(y, lam), its reference magnitude rref (the test is
        !> ||r|| <= tol_r rref) and rlam = dR/dlam. When jac is true, also factorise
        !> J = dR/dy for `solve`.
        subroutine eval_iface(this, y, lam, r, rref, jac, rlam, info, errmsg)
            import :: nl_system, wp, ip
            class(nl_system), intent(inout) :: this
            real(wp), intent(in) :: y(:)        !! (n) unknowns
            real(wp), intent(in) :: lam         !! parameter
            real(wp), intent(out) :: r(:)       !! (n) residual
            real(wp), intent(out) :: rref       !! reference magnitude of the residual
            logical, intent(in) :: jac          !! factorise dR/dy
            real(wp), intent(out) :: rlam(:)    !! (n) dR/dlam
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine eval_iface
        !> Overwrite the columns of b with J^-1 b, J from the last eval with jac.
        subroutine solve_iface(this, b, info, errmsg)
            import :: nl_system, wp, ip
            class(nl_system), intent(inout) :: this
            real(wp), intent(inout) :: b(:, :)  !! (n, nrhs)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine solve_iface
    end interface

    !> Newton and continuation settings. Arc length is measured in scaled variables
    !> (y / yscale, lam / lscale), so ds is dimensionless.
    type :: cont_options
        real(wp) :: tol_r = 1.0e-10_wp   !! ||R|| / rref below this ...
        real(wp) :: tol_x = 1.0e-9_wp    !! ... and ||dy|| / max(||y||, yscale) below this
        !> after max_iter, a residual that stagnated below this is accepted: at a contact
        !> state change inside one time sample R is not differentiable and Newton can cycle
        !> between the two sides at a level far below the AFT discretisation error
        real(wp) :: tol_stall = 0.0_wp
        integer(ip) :: max_iter = 25     !! Newton iterations per corrector
        logical :: reuse_jac = .true.    !! keep a factorisation while iterations contract
        real(wp) :: reuse_rate = 0.1_wp  !! contraction factor below which J is kept
        real(wp) :: yscale = 1.0_wp      !! typical size of y (e.g. linear response norm)
        real(wp) :: lscale = 1.0_wp      !! typical size of lam (e.g. frequency range)
        real(wp) :: ds = 0.01_wp         !! initial arc-length step
        real(wp) :: ds_min = 1.0e-6_wp
        real(wp) :: ds_max = 0.1_wp
        integer(ip) :: iter_target = 4   !! steps may grow below, shrink above this
        !> step control on the curve's shape: the angle (rad) between the tangents at the
        !> two ends of a step, and the distance from predictor to corrected point (scaled
        !> variables), each aimed at per step; the angle grows like ds, the distance like ds^2
        real(wp) :: angle_target = 0.2_wp
        real(wp) :: dist_target = 0.02_wp
        real(wp) :: grow_max = 2.0_wp    !! largest step growth factor per point
        real(wp) :: lam_end = 1.0_wp     !! continuation stops at this parameter value
        integer(ip) :: max_points = 1000 !! points per call
    end type cont_options

contains

    !> Continuation settings from their flat layout (slots RCONT_*, ICONT_*; reuse_jac is
    !> true for a nonzero integer); fields without a slot keep their defaults.
    pure function cont_options_from(rv, iv) result(opts)
        real(wp), intent(in) :: rv(N_RCONT)     !! real settings by RCONT_* slot
        integer(ip), intent(in) :: iv(N_ICONT)  !! integer settings by ICONT_* slot
        type(cont_options) :: opts
        opts%tol_r = rv(RCONT_TOL_R)
        opts%tol_x = rv(RCONT_TOL_X)
        opts%tol_stall = rv(RCONT_TOL_STALL)
        opts%yscale = rv(RCONT_YSCALE)
        opts%lscale = rv(RCONT_LSCALE)
        opts%ds = rv(RCONT_DS)
        opts%ds_min = rv(RCONT_DS_MIN)
        opts%ds_max = rv(RCONT_DS_MAX)
        opts%lam_end = rv(RCONT_LAM_END)
        opts%max_iter = iv(ICONT_MAX_ITER)
        opts%reuse_jac = iv(ICONT_REUSE_JAC) /= 0
    end function cont_options_from

    !> Called once per converged point (y, lam), before its tangent is computed: a system
    !> with history (friction sliders) updates the state that R depends on here, so that
    !> R(y) stays one deterministic function during each corrector. Default: nothing.
    subroutine nl_accept(this, y, lam, info, errmsg)
        class(nl_system), intent(inout) :: this
        real(wp), intent(in) :: y(:)        !! (n) converged unknowns
        real(wp), intent(in) :: lam         !! converged parameter
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = FRIROM_OK
        if (.false.) errmsg = ''
        if (.false.) this%n = size(y) + int(lam)
    end subroutine nl_accept

    !> Called as a corrector starts: a system whose residual holds choices of its first
    !> evaluation through the corrector (frirom_hbm: the 2-D sliders' period counts)
    !> makes them afresh here. Default: nothing.
    subroutine nl_begin_correct(this)
        class(nl_system), intent(inout) :: this
        if (.false.) this%n = this%n + 0
    end subroutine nl_begin_correct

    !> Whether the choices begin_correct clears, held since, still hold at the point of the
    !> last evaluation (frirom_hbm: every held 2-D history cycle closes there). A corrector
    !> that converges where they do not makes them afresh there and goes on. Default: yes.
    logical function nl_settled(this) result(yes)
        class(nl_system), intent(in) :: this
        yes = this%n >= 0
    end function nl_settled

    !> Whether the residual r (rref from the same eval) is at the round-off level of its
    !> terms, where Newton accepts a point whatever its last update (a near-singular J,
    !> e.g. gross slip, can keep the update above tol_x there): ||r|| <= 100 eps rref. A
    !> system whose residual falls into blocks of very different scales (a static preload
    !> at harmonic 0, the vibration harmonics) overrides it with a test per block.
    function nl_roundoff(this, r, rref) result(yes)
        class(nl_system), intent(in) :: this
        real(wp), intent(in) :: r(:)        !! (n) residual
        real(wp), intent(in) :: rref        !! its reference magnitude
        logical :: yes
        yes = norm2(r) <= 100.0_wp*epsilon(1.0_wp)*rref
        if (.false.) yes = this%n < 0
    end function nl_roundoff

    !> Bordered Newton corrector: solve R(y, lam) = 0 together with the linear constraint
    !> cy.(y - yp)/yscale + cl (lam - lp)/lscale = 0 (cy = 0, cl = 1 fixes lam = lp;
    !> cy, cl = tangent gives pseudo-arc-length). y, lam enter as the start, leave solved.
    subroutine newton_correct(sys, y, lam, yp, lp, cy, cl, opts, iters, info, errmsg, &
                              have_fact, nfact, stalled, stall_window)
        class(nl_system), intent(inout) :: sys
        real(wp), intent(inout) :: y(:)       !! (n) start in, solution out
        real(wp), intent(inout) :: lam        !! start in, solution out
        real(wp), intent(in) :: yp(:), lp     !! (n), predicted point of the constraint
        real(wp), intent(in) :: cy(:), cl     !! (n), constraint direction (scaled)
        type(cont_options), intent(in) :: opts
        integer(ip), intent(out) :: iters     !! Newton iterations used
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        logical, intent(inout) :: have_fact   !! a usable factorisation exists (in/out)
        integer(ip), intent(out), optional :: nfact  !! Jacobian factorisations made
        !> give up after this many iterations without halving the merit (absent: only
        !> after max_iter); stalled: it gave up so
        integer(ip), intent(in), optional :: stall_window
        logical, intent(out), optional :: stalled
        real(wp), allocatable :: r(:), rlam(:), ab(:, :), y1(:), r1(:), dy(:), rlam1(:)
        real(wp) :: rref, rn, g, denom, dlam, alpha, phi0, phi1, rn1, rref1, g1, lam1, dxn
        real(wp) :: rate
        logical :: fresh, jac_trial, jac_at_y
        !> converged where the choices held since the corrector began no longer hold
        !> (settled): made afresh at most this many times
        integer(ip), parameter :: MAX_REARMS = 3
        integer(ip) :: rearms, kref, window
        real(wp) :: mref
        character(len=120) :: buf
        integer(ip) :: n, k
        n = sys%n
        info = FRIROM_OK
        iters = 0
        if (size(y) /= n .or. size(yp) /= n .or. size(cy) /= n) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'newton_correct: y, yp, cy need n')
            return
        end if
        allocate (r(n), rlam(n), ab(n, 2), y1(n), r1(n), dy(n), rlam1(n))
        call sys%begin_correct()
        if (present(stalled)) stalled = .false.
        window = opts%max_iter
        if (present(stall_window)) window = stall_window
        rearms = 0
        rate = 1.0_wp
        fresh = .not. (have_fact .and. opts%reuse_jac)
        if (present(nfact)) nfact = merge(1, 0, fresh)
        call sys%eval(y, lam, r, rref, fresh, rlam, info, errmsg)
        if (info /= 0) return
        have_fact = .true.
        rn = norm2(r)/max(rref, tiny(1.0_wp))
        g = dot_product(cy, y - yp)/opts%yscale + cl*(lam - lp)/opts%lscale
        mref = hypot(rn, g)
        kref = 0
        ! without chord steps every iteration takes J at its point: the line search's
        ! trial evaluations take it too, and the next iteration needs no evaluation
        jac_trial = .not. opts%reuse_jac
        jac_at_y = .false.
        do k = 1, opts%max_iter
            iters = k
            if (k > 1 .and. jac_at_y) then
                fresh = .true.
            else if (k > 1 .and. (.not. opts%reuse_jac .or. rate > opts%reuse_rate)) then
                call sys%eval(y, lam, r, rref, .true., rlam, info, errmsg)
                if (info /= 0) return
                fresh = .true.
                if (present(nfact)) nfact = nfact + 1
            else if (k > 1) then
                fresh = .false.
            end if
            ab(:, 1) = -r
            ab(:, 2) = rlam
            call sys%solve(ab, info, errmsg)
            if (info /= 0) return
            denom = cl/opts%lscale - dot_product(cy, ab(:, 2))/opts%yscale
            if (abs(denom) < tiny(1.0_wp)) then
                call set_status(info, FRIROM_ERR_NOCONV, errmsg, &
                                'newton_correct: constraint parallel to the solution curve')
                return
            end if
            dlam = (-g - dot_product(cy, ab(:, 1))/opts%yscale)/denom
            dy = ab(:, 1) - dlam*ab(:, 2)
            if (.not. (all(abs(dy) <= huge(1.0_wp)) .and. abs(dlam) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_NONFINITE, errmsg, &
                                'newton_correct: non-finite Newton update')
                return
            end if
            ! converged without the residual at y + dy: R(y) met its test and the full
            ! update is below tol_x, the tests the evaluation there would pass (R moves by
            ! J dy). The caller evaluates the point again anyway (accept, cont_tangent).
            if (rn <= opts%tol_r .and. abs(g) <= max(opts%tol_x, 1.0e-12_wp)) then
                y1 = y + dy
                if (max(norm2(dy)/max(norm2(y1), opts%yscale), abs(dlam)/opts%lscale) <= &
                    opts%tol_x) then
                    y = y1
                    lam = lam + dlam
                    if (sys%settled() .or. rearms >= MAX_REARMS) return
                    call rearm()
                    if (info /= 0) return
                    cycle
                end if
            end if
            ! backtracking on the merit ||R||^2/rref^2 + g^2
            phi0 = rn**2 + g**2
            alpha = 1.0_wp
            do
                y1 = y + alpha*dy
                lam1 = lam + alpha*dlam
                call sys%eval(y1, lam1, r1, rref1, jac_trial, rlam1, info, errmsg)
                if (info /= 0) return
                if (jac_trial .and. present(nfact)) nfact = nfact + 1
                rn1 = norm2(r1)/max(rref1, tiny(1.0_wp))
                g1 = dot_product(cy, y1 - yp)/opts%yscale + cl*(lam1 - lp)/opts%lscale
                phi1 = rn1**2 + g1**2
                if (phi1 <= (1.0_wp - 1.0e-4_wp*alpha)*phi0 .or. alpha < 0.06_wp) exit
                if (.not. (phi1 <= huge(1.0_wp)) .and. alpha < 0.06_wp) exit
                alpha = 0.5_wp*alpha
            end do
            if (.not. (phi1 <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_NONFINITE, errmsg, &
                                'newton_correct: residual not finite along the update')
                return
            end if
            dxn = alpha*max(norm2(dy)/max(norm2(y1), opts%yscale), &
                            abs(dlam)/opts%lscale)
            rate = sqrt(phi1/max(phi0, tiny(1.0_wp)))
            y = y1
            lam = lam1
            jac_at_y = jac_trial
            r = r1
            rlam = rlam1
            rref = rref1
            rn = rn1
            g = g1
            ! converged: residual and update small; or the residual at round-off level
            ! (near-singular J, e.g. gross slip, can keep the update above tol_x there)
            if (rn <= opts%tol_r .and. abs(g) <= max(opts%tol_x, 1.0e-12_wp) .and. &
                (dxn <= opts%tol_x .or. sys%roundoff(r, rref))) then
                if (sys%settled() .or. rearms >= MAX_REARMS) return
                call rearm()
                if (info /= 0) return
            else if (hypot(rn, g) < 0.5_wp*mref) then
                mref = hypot(rn, g)
                kref = k
            else if (k - kref >= window) then
                exit
            end if
        end do
        if (rn <= opts%tol_stall .and. abs(g) <= max(opts%tol_x, 1.0e-12_wp)) return
        if (present(stalled)) stalled = iters < opts%max_iter
        call set_status(info, FRIROM_ERR_NOCONV, errmsg, 'newton_correct: no convergence')
        write (buf, '(a,i0,a,es9.2,a,es9.2)') ' in ', iters, ' iterations, |R|/rref = ', &
            rn, ', update = ', dxn
        if (iters < opts%max_iter) buf = ' (stalled)'//buf
        errmsg = trim(errmsg)//trim(buf)
    contains
        !> The choices afresh at y (its Jacobian with them), and Newton goes on from there.
        subroutine rearm()
            rearms = rearms + 1
            call sys%begin_correct()
            call sys%eval(y, lam, r, rref, .true., rlam, info, errmsg)
            if (info /= 0) return
            if (present(nfact)) nfact = nfact + 1
            rn = norm2(r)/max(rref, tiny(1.0_wp))
            g = dot_product(cy, y - yp)/opts%yscale + cl*(lam - lp)/opts%lscale
            jac_at_y = .true.
            rate = 1.0_wp
            mref = hypot(rn, g)
            kref = k
        end subroutine rearm
    end subroutine newton_correct

    !> Unit tangent (scaled variables) of the solution curve at a converged point, oriented
    !> along `tprev` (or along increasing lam * sgn when tprev is zero). With `orient`
    !> (in/out) on a system of at most DET_MAX_N unknowns the orientation is the curve's
    !> own instead: sign(det J) sign(t_lam), the sign of the determinant of the bordered
    !> matrix [J, R_lam; t^T], stays the same along a curve through folds and through
    !> the corners where contact states switch (it changes only where the curve is
    !> retraced); orient 0 on entry takes it from the tprev orientation here. Leaves the
    !> factorisation of J at this point in the system, for the next corrector.
    subroutine cont_tangent(sys, y, lam, opts, tprev, sgn, t, info, errmsg, orient, by_det)
        class(nl_system), intent(inout) :: sys
        real(wp), intent(in) :: y(:), lam
        type(cont_options), intent(in) :: opts
        real(wp), intent(in) :: tprev(:)      !! (n+1) previous tangent, or zeros
        real(wp), intent(in) :: sgn           !! direction of lam when tprev is zero
        real(wp), intent(out) :: t(:)         !! (n+1) unit tangent (y/yscale, lam/lscale)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), intent(inout), optional :: orient  !! +-1 the curve's orientation, 0 unset
        logical, intent(out), optional :: by_det     !! t oriented by orient
        real(wp), allocatable :: r(:), rlam(:), b(:, :)
        real(wp) :: rref, nrm, dsg
        integer(ip) :: n
        n = sys%n
        allocate (r(n), rlam(n), b(n, 1))
        call sys%eval(y, lam, r, rref, .true., rlam, info, errmsg)
        if (info /= 0) return
        b(:, 1) = rlam
        call sys%solve(b, info, errmsg)
        if (info /= 0) return
        ! dy/dlam = -J^-1 dR/dlam, in scaled variables
        t(1:n) = -b(:, 1)*opts%lscale/opts%yscale
        t(n + 1) = 1.0_wp
        nrm = norm2(t)
        if (.not. (nrm <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_NONFINITE, errmsg, 'cont_tangent: J singular?')
            return
        end if
        t = t/nrm
        dsg = 0.0_wp
        if (present(by_det)) by_det = .false.
        if (present(orient)) then
            if (n <= DET_MAX_N) call jac_det_sign(sys, dsg, info, errmsg)
            if (info /= 0) return
        end if
        if (dsg /= 0.0_wp .and. orient /= 0.0_wp) then
            ! t(n + 1) > 0 here: the sign that keeps sign(det J) t_lam the curve's
            t = (orient*dsg)*t
            if (present(by_det)) by_det = .true.
            return
        end if
        if (any(tprev /= 0.0_wp)) then
            if (dot_product(t, tprev) < 0.0_wp) t = -t
        else
            if (t(n + 1)*sgn < 0.0_wp) t = -t
        end if
        if (dsg /= 0.0_wp) orient = dsg*sign(1.0_wp, t(n + 1))
    end subroutine cont_tangent

    !> Sign of det J (+-1), J as the last eval with jac factorised it: J^-1 by n solves,
    !> then its LU (for small systems only: n solves and an n^3 LU); 0 where it says
    !> nothing: J^-1 not finite, or J singular to the working precision (pivots of J^-1
    !> spread by more than 1e10: a direction the equations leave free, e.g. a slider's
    !> mean position in gross slip, where the sign is rounding).
    subroutine jac_det_sign(sys, dsg, info, errmsg)
        class(nl_system), intent(inout) :: sys
        real(wp), intent(out) :: dsg
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: x(:, :)
        integer(ip), allocatable :: ipiv(:)
        integer(ip) :: n, i, linfo
        n = sys%n
        dsg = 0.0_wp
        allocate (x(n, n), ipiv(n))
        x = 0.0_wp
        do i = 1, n
            x(i, i) = 1.0_wp
        end do
        call sys%solve(x, info, errmsg)
        if (info /= 0 .or. .not. all(abs(x) <= huge(1.0_wp))) return
        call dgetrf(n, n, x, n, ipiv, linfo)
        if (linfo /= 0) return
        if (maxval(abs([(x(i, i), i=1, n)])) > 1.0e10_wp*minval(abs([(x(i, i), i=1, n)]))) &
            return
        dsg = 1.0_wp
        do i = 1, n
            if (ipiv(i) /= i) dsg = -dsg
            if (x(i, i) < 0.0_wp) dsg = -dsg
        end do
    end subroutine jac_det_sign

    !> Pseudo-arc-length continuation from a converged point (y, lam) with tangent t,
    !> until lam reaches opts%lam_end (the last point is solved at lam_end exactly), the
    !> curve leaves the range through lam_lo, or max_points points were made. A failed
    !> corrector is retried with half the step; below ds_min the run stops with
    !> FRIROM_ERR_CONT and every point made so far stays in the outputs. A converged step
    !> longer than ds_max / 4 whose predictor-corrector distance says it was more than
    !> twice too long for the curve's shape is retried once with the step
    !> cont_step_factor gives. With `orient` (see cont_tangent) a point whose chord runs
    !> against the curve's orientation there, the curve retraced (at a near-fold the
    !> corrector or turn_corner can land on the branch just left), is rejected like a
    !> failed corrector.
    subroutine cont_run(sys, y, lam, t, ds, lam_lo, opts, yout, lout, tout, itout, npts, &
                        finished, info, errmsg, have_fact, tj, orient)
        class(nl_system), intent(inout) :: sys
        real(wp), intent(inout) :: y(:)        !! (n) start point in, last point out
        real(wp), intent(inout) :: lam
        real(wp), intent(inout) :: t(:)        !! (n+1) tangent in/out
        real(wp), intent(inout) :: ds          !! step in/out (adapted)
        real(wp), intent(in) :: lam_lo         !! stop if the curve turns back past this
        type(cont_options), intent(in) :: opts
        real(wp), intent(out) :: yout(:, :)    !! (n, max_points) converged points
        real(wp), intent(out) :: lout(:)       !! (max_points)
        real(wp), intent(out) :: tout(:, :)    !! (n+1, max_points) tangents
        integer(ip), intent(out) :: itout(:)   !! (max_points) Newton iterations
        integer(ip), intent(out) :: npts       !! points made
        logical, intent(out) :: finished       !! lam_end (or lam_lo) reached
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        logical, intent(inout) :: have_fact    !! the system holds J at (y, lam) (in/out)
        !> (n+1) the unit tangent J gives at (y, lam), in/out: t itself unless a chord
        !> replaced it (the secant rule); absent, t is taken for it at the start
        real(wp), intent(inout), optional :: tj(:)
        real(wp), intent(inout), optional :: orient  !! +-1 the curve's orientation, 0 unset
        real(wp), allocatable :: y1(:), yp(:), t1(:), cy(:), ch(:), tjl(:)
        real(wp) :: lam1, lp, dirn, frac, cl, angle, dist
        integer(ip) :: n, iters
        logical :: last, turned, retried, by_det, stalled
        !> a corrector gives up after this many iterations without halving its merit: its
        !> residual stalled where R is not smooth (a contact switching inside a time
        !> sample), and a shorter step is cheaper than max_iter iterations and a retry (a
        !> BRB backbone corrector sat at |R|/rref ~8e-7 for 13 iterations with fresh
        !> Jacobians and line searches, then as long in the retry). Only in continuation:
        !> a solve from a far start (a probe) may take longer to find its way
        integer(ip), parameter :: STALL_WINDOW = 5
        integer(ip) :: nf, effort
        type(cont_options) :: fresh_opts
        character(len=len(errmsg)) :: why
        character(len=120) :: buf
        n = sys%n
        info = FRIROM_OK
        npts = 0
        finished = .false.
        if (size(y) /= n .or. size(t) /= n + 1 .or. size(yout, 1) /= n .or. &
            size(tout, 1) /= n + 1 .or. size(yout, 2) < opts%max_points .or. &
            size(lout) < opts%max_points .or. size(itout) < opts%max_points) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'cont_run: array sizes')
            return
        end if
        if (.not. (ds > 0.0_wp .and. opts%ds_min > 0.0_wp .and. opts%ds_max >= opts%ds_min)) &
            then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'cont_run: need 0 < ds_min <= '// &
                            'ds_max and ds > 0')
            return
        end if
        allocate (y1(n), yp(n), t1(n + 1), cy(n), ch(n + 1))
        tjl = t
        if (present(tj)) tjl = tj
        dirn = sign(1.0_wp, opts%lam_end - lam_lo)
        fresh_opts = opts
        fresh_opts%reuse_jac = .false.
        retried = .false.
        do while (npts < opts%max_points)
            ds = min(max(ds, opts%ds_min), opts%ds_max)
            yp = y + ds*t(1:n)*opts%yscale
            lp = lam + ds*t(n + 1)*opts%lscale
            last = (lp - opts%lam_end)*dirn >= 0.0_wp
            if (last) then
                ! land on lam_end: fixed-parameter corrector from the interpolated predictor
                frac = (opts%lam_end - lam)/(lp - lam)
                yp = y + frac*(yp - y)
                lp = opts%lam_end
                cy = 0.0_wp
                cl = 1.0_wp
            else
                cy = t(1:n)
                cl = t(n + 1)
            end if
            y1 = yp
            lam1 = lp
            call newton_correct(sys, y1, lam1, yp, lp, cy, cl, opts, iters, info, errmsg, &
                                have_fact, nf, stalled, STALL_WINDOW)
            if (info /= 0 .and. opts%reuse_jac .and. .not. stalled) then
                ! chord steps can stall where a contact changes state: retry the same step
                ! with a fresh Jacobian at every iteration before shrinking it (not after a
                ! stall, which took fresh Jacobians already: the retry stalls alike)
                y1 = yp
                lam1 = lp
                have_fact = .false.
                call newton_correct(sys, y1, lam1, yp, lp, cy, cl, fresh_opts, iters, info, &
                                    errmsg, have_fact, nf)
            end if
            if (info == 0 .and. .not. last) then
                ! a corrector that wandered far from the predictor found another branch, or
                ! met this one far off because it turns at a corner (then turn_corner)
                if (sqrt(sum(((y1 - y)/opts%yscale)**2) + ((lam1 - lam)/opts%lscale)**2) > &
                    3.0_wp*ds) then
                    call set_status(info, FRIROM_ERR_NOCONV, errmsg, 'corrector converged '// &
                                    'more than 3 steps away from the predictor')
                end if
            end if
            turned = .false.
            if (info /= 0 .and. .not. last) call turn_corner(sys, y, lam, t, tjl, ds, &
                                                             fresh_opts, y1, lam1, t1, iters, &
                                                             nf, turned, info, errmsg, &
                                                             have_fact, orient)
            if (info == 0 .and. .not. (last .or. retried .or. turned) .and. &
                ds > 0.25_wp*opts%ds_max) then
                ! a long step far too long for the curve's shape (the corrector moved off
                ! the predictor by much more than the targets allow, e.g. across a resonance
                ! narrower than the step) is retried once, shorter, before its point counts;
                ! short steps are not (at a corner of the curve, a contact state switching,
                ! the ratio stays whatever the step)
                dist = sqrt(sum(((y1 - yp)/opts%yscale)**2) + ((lam1 - lp)/opts%lscale)**2)
                frac = cont_step_factor(2.0_wp*atan2(dist, ds), dist, 0_ip, opts)
                if (frac < 0.5_wp) then
                    retried = .true.
                    have_fact = .false.
                    ds = frac*ds
                    cycle
                end if
            end if
            if (info /= 0) then
                why = errmsg
                have_fact = .false.
                if (ds <= opts%ds_min*1.000001_wp) then
                    call set_status(info, FRIROM_ERR_CONT, errmsg, 'continuation stopped')
                    write (buf, '(a,es12.5,a,es9.2,a)') ' at parameter ', lam, &
                        ' with step ', ds, ' at its minimum; last corrector: '
                    errmsg = trim(errmsg)//trim(buf)//' '//trim(why)
                    return
                end if
                info = FRIROM_OK
                ds = 0.5_wp*ds
                cycle
            end if
            call sys%accept(y1, lam1, info, errmsg)
            ! after a corner the new tangent is oriented along the branch taken (t1)
            if (turned) t = t1
            if (info == 0) call cont_tangent(sys, y1, lam1, opts, t, dirn, t1, info, errmsg, &
                                             orient, by_det)
            if (info /= 0) then
                have_fact = .false.
                return
            end if
            if (.not. last .and. by_det .and. retraced(y, lam, y1, lam1, t1, opts, orient)) then
                if (ds > opts%ds_min*1.000001_wp) then
                    ! the curve retraced: a shorter step (as after a failed corrector)
                    have_fact = .false.
                    ds = 0.5_wp*ds
                    cycle
                end if
                ! still at the minimum step: the determinant's sign is not trusted here (a
                ! coarse AFT's corner can flip it, e.g. the joint at H = 5, N = 32): the
                ! point is taken with its tangent along the previous one, as without the
                ! orientation, which the next point takes up again (orient 0)
                if (dot_product(t1, t) < 0.0_wp) t1 = -t1
                orient = 0.0_wp
            end if
            have_fact = .true.
            retried = .false.
            npts = npts + 1
            tjl = t1
            if (present(tj)) tj = tjl
            if (.not. last) then
                ! the curve has a corner at the new point: its tangent turns more than 60
                ! degrees from the chord that reached it, or 3 angle_target once steps
                ! have shrunk below ds_max / 20 (carried contact history: sliders left
                ! where they last slipped make every point of a rising response a corner
                ! between the stick tangent J gives and the slip branch ahead, 40-80
                ! degrees on the paper_hooks ROM_II). Predict along the chord (secant).
                ch(1:n) = (y1 - y)/opts%yscale
                ch(n + 1) = (lam1 - lam)/opts%lscale
                if (chord_wins(ch, t1, t, ds, opts) .and. .not. &
                    (by_det .and. ch(n + 1)*t1(n + 1) < 0.0_wp)) t1 = ch/norm2(ch)
            end if
            angle = acos(max(-1.0_wp, min(1.0_wp, dot_product(t, t1))))
            dist = 0.0_wp
            if (.not. (last .or. turned)) dist = sqrt(sum(((y1 - yp)/opts%yscale)**2) + &
                                        ((lam1 - lp)/opts%lscale)**2)
            y = y1
            lam = lam1
            t = t1
            yout(:, npts) = y
            lout(npts) = lam
            tout(:, npts) = t
            itout(npts) = iters
            ! the work done: Newton iterations, or with Jacobian reuse the factorisations
            ! (chord iterations are cheap)
            effort = iters
            if (opts%reuse_jac) effort = min(iters, 2*nf)
            ds = min(max(ds*cont_step_factor(angle, dist, effort, opts), opts%ds_min), &
                     opts%ds_max)
            if (last .or. (lam - lam_lo)*dirn < 0.0_wp) then
                finished = .true.
                return
            end if
        end do
    end subroutine cont_run

    !> Corrector past a corner of the solution curve, after the one across the tangent t
    !> at (y, lam) failed. A contact state switching at one AFT sample makes R piecewise
    !> smooth; near a resonance the curve can turn there by 90 degrees or more, and then
    !> no hyperplane across t meets the branch beyond the corner, at any step. The
    !> tangent tc at the predictor (on the far side of the corner) gives the new
    !> direction: the corrector runs across tc, oriented along t first, then against it.
    !> A point is taken (turned true, tc its direction) only if it lies within 3 ds and
    !> its chord turns by less than 120 degrees from t (never back along the curve).
    !> Where t is a chord, not the tangent tj J gives at (y, lam) (a carried contact history:
    !> J gives the stick tangent and every point is a corner), the tangent at the predictor
    !> says nothing about a corner while the step is long: a failure there is a step too
    !> long, halved first (nothing is tried above ds_max / 20); and a point against the
    !> parameter's direction of travel is the frozen history's branch behind (y, lam), not
    !> the curve ahead: it is never taken.
    subroutine turn_corner(sys, y, lam, t, tj, ds, opts, y1, lam1, tc, iters, nf, turned, &
                           info, errmsg, have_fact, orient)
        class(nl_system), intent(inout) :: sys
        real(wp), intent(in) :: y(:), lam     !! (n) last converged point
        real(wp), intent(in) :: t(:)          !! (n+1) its unit tangent (scaled)
        real(wp), intent(in) :: tj(:)         !! (n+1) the unit tangent J gives there
        real(wp), intent(in) :: ds            !! step (scaled)
        type(cont_options), intent(in) :: opts
        real(wp), intent(out) :: y1(:), lam1  !! (n) the point past the corner
        real(wp), intent(out) :: tc(:)        !! (n+1) direction taken (unit, scaled)
        integer(ip), intent(out) :: iters, nf
        logical, intent(out) :: turned
        integer(ip), intent(inout) :: info    !! in: the failed corrector's status
        character(len=*), intent(inout) :: errmsg
        logical, intent(inout) :: have_fact
        real(wp), intent(in), optional :: orient  !! the curve's orientation (cont_tangent)
        real(wp), allocatable :: yp(:), ch(:), tk(:)
        real(wp) :: lp, dch, ork
        integer(ip) :: n, k, info2
        logical :: ratchet, by_det
        character(len=len(errmsg)) :: msg2
        n = size(y)
        turned = .false.
        iters = 0
        nf = 0
        allocate (yp(n), ch(n + 1), tk(n + 1))
        ! is t the tangent J gives here, or a chord (see cont_run)?
        ratchet = abs(dot_product(tj, t)) < secant_cos(ds, opts)
        if (ratchet .and. ds >= 0.05_wp*opts%ds_max) then
            have_fact = .false.
            return
        end if
        yp = y + ds*t(1:n)*opts%yscale
        lp = lam + ds*t(n + 1)*opts%lscale
        msg2 = ''
        call cont_tangent(sys, yp, lp, opts, t, 1.0_wp, tc, info2, msg2)
        have_fact = .false.
        ! no corner: the tangent hardly turns (the failure has another cause)
        if (info2 /= 0 .or. dot_product(tc, t) > 0.9_wp) return
        do k = 1, 2
            if (k == 2) tc = -tc
            yp = y + ds*tc(1:n)*opts%yscale
            lp = lam + ds*tc(n + 1)*opts%lscale
            y1 = yp
            lam1 = lp
            msg2 = ''
            call newton_correct(sys, y1, lam1, yp, lp, tc(1:n), tc(n + 1), opts, iters, info2, &
                                msg2, have_fact, nf)
            if (info2 /= 0) cycle
            ch(1:n) = (y1 - y)/opts%yscale
            ch(n + 1) = (lam1 - lam)/opts%lscale
            dch = norm2(ch)
            if (dch <= 3.0_wp*ds .and. dot_product(ch, t) >= -0.5_wp*dch .and. &
                .not. (ratchet .and. ch(n + 1)*t(n + 1) < 0.0_wp)) then
                if (present(orient)) then
                    ! the branch just left, taken backward, is no way past the corner
                    msg2 = ''
                    ork = orient
                    call cont_tangent(sys, y1, lam1, opts, tc, 1.0_wp, tk, info2, msg2, ork, &
                                      by_det)
                    have_fact = .false.
                    if (info2 /= 0) cycle
                    if (by_det .and. retraced(y, lam, y1, lam1, tk, opts, ork)) cycle
                end if
                turned = .true.
                info = FRIROM_OK
                return
            end if
        end do
        have_fact = .false.
    end subroutine turn_corner

    !> Whether the step from (y, lam) to (y1, lam1) ran against t1, the tangent at the new
    !> point in the curve's orientation (orient nonzero, cont_tangent): it went back along
    !> the curve. False without an orientation.
    logical function retraced(y, lam, y1, lam1, t1, opts, orient)
        real(wp), intent(in) :: y(:), lam, y1(:), lam1
        real(wp), intent(in) :: t1(:)          !! (n+1) unit tangent at (y1, lam1)
        type(cont_options), intent(in) :: opts
        real(wp), intent(in), optional :: orient
        integer(ip) :: n
        retraced = .false.
        if (.not. present(orient)) return
        if (orient == 0.0_wp) return
        n = size(y)
        retraced = dot_product(t1(1:n), (y1 - y)/opts%yscale) + &
                   t1(n + 1)*(lam1 - lam)/opts%lscale < 0.0_wp
    end function retraced

    !> Whether the chord ch that reached a point (scaled, not unit; ch(n+1) the parameter)
    !> replaces the tangent tj that J gives there (unit, oriented along tprev, the tangent
    !> the step left from) as the direction of the next step: they differ by more than
    !> secant_cos says (a corner of the curve), unless the chord reverses the parameter's
    !> direction of travel (tprev's) while tj keeps it. Such a chord is no fold: where
    !> the step was near the corrector's tolerance, at a corner of a contact state, it
    !> pointed backward by corrector noise (the paper hooks ROM_II, 1e-8 rad/s back), and
    !> predicting along it made the run turn back.
    pure logical function chord_wins(ch, tj, tprev, ds, opts)
        real(wp), intent(in) :: ch(:)          !! (n+1) y1 - y, lam1 - lam (scaled)
        real(wp), intent(in) :: tj(:)          !! (n+1) J's unit tangent at the point
        real(wp), intent(in) :: tprev(:)       !! (n+1) the previous point's tangent
        real(wp), intent(in) :: ds             !! the step (scaled)
        type(cont_options), intent(in) :: opts
        integer(ip) :: m
        real(wp) :: dist
        m = size(ch)
        dist = norm2(ch)
        chord_wins = dist > 0.0_wp .and. dot_product(ch, tj) < secant_cos(ds, opts)*dist
        if (ch(m)*tprev(m) < 0.0_wp .and. tj(m)*tprev(m) > 0.0_wp) chord_wins = .false.
    end function chord_wins

    !> Cosine below which the tangent J gives at a point is replaced by the chord that
    !> reached it (60 degrees; 3 angle_target once steps have shrunk below ds_max / 20).
    pure real(wp) function secant_cos(ds, opts)
        real(wp), intent(in) :: ds             !! the step (scaled)
        type(cont_options), intent(in) :: opts
        secant_cos = 0.5_wp
        if (ds < 0.05_wp*opts%ds_max) secant_cos = cos(3.0_wp*opts%angle_target)
    end function secant_cos

    !> Factor on the arc-length step after a point: the curve's shape sets it (the angle
    !> between the tangents at the step's ends grows like ds, the predictor-corrector
    !> distance like ds^2: each is brought to its target), the Newton effort limits it
    !> (no growth at iter_target or more, shrink by 0.6 above iter_target + 2), and it
    !> lies in [1/4, grow_max]. Deterministic: no timing enters.
    pure function cont_step_factor(angle, dist, effort, opts) result(f)
        real(wp), intent(in) :: angle          !! rad between successive unit tangents
        real(wp), intent(in) :: dist           !! predictor-corrector distance (scaled)
        integer(ip), intent(in) :: effort      !! Newton iterations (or factorisations)
        type(cont_options), intent(in) :: opts
        real(wp) :: f
        f = opts%grow_max
        if (angle*f > opts%angle_target) f = opts%angle_target/angle
        if (dist*f**2 > opts%dist_target) f = sqrt(opts%dist_target/dist)
        if (effort > opts%iter_target + 2) then
            f = min(f, 0.6_wp)
        else if (effort > opts%iter_target - 1) then
            f = min(f, 1.0_wp)
        end if
        f = max(f, 0.25_wp)
    end function cont_step_factor
end module frirom_newton
