!> The linear solves of a condensed system: when J is factorised (a new LU, or GMRES on
!> J preconditioned by the LU held from an older J), the LU itself (single precision
!> with a Woodbury correction for systems that hold it), the solves, J applied
!> matrix-free, and forgetting the LU held (hbm_lu_forget). The LU, GMRES and Woodbury
!> kernels are frirom_linsolve's; the policy is here.
submodule (frirom_hbm:frirom_hbm_condensed) frirom_hbm_factor
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, &
                             FRIROM_ERR_SINGULAR, set_status
    use frirom_status, only: FRIROM_ERR_SIZE, FRIROM_ERR_PARAM
    use frirom_linsolve, only: lin_operator, fgmres, held_lu_factor, held_lu_apply, &
                               woodbury_reset, woodbury_alloc, woodbury_finish, &
                               woodbury_prepare
    implicit none

    !> GMRES (Krylov mode): relative residual, iteration limit before the J is factorised,
    !> iterations above which the next J is factorised.
    real(wp), parameter :: GM_TOL = 1.0e-11_wp
    integer(ip), parameter :: GM_MAXIT = 40, GM_REFRESH = 8
    !> Direct mode, modal route: the first solve after an eval with jac is GMRES on that
    !> J preconditioned by the LU held (of an older J), to this relative residual. An LU
    !> is worth lu_worth GMRES iterations (flops of each, the LU's counted
    !> LU_SPEEDUP times faster, blocked against memory-bound); J is factorised instead
    !> once the iterations since the last LU reach that, or when one solve needs more
    !> than a third of it (at least GN_MINIT); always when an LU is worth less than
    !> GN_WORTH_MIN iterations (a few hundred unknowns: LUs are cheap and each Newton
    !> path stays the one of the LUs). Deterministic: sizes and counts only. GN_TOL is
    !> an inexact Newton step's: Newton's own residual test decides convergence, and 1e-4
    !> took 1/3 fewer GMRES iterations than 1e-8 with no more evaluations on the
    !> large_interface scaling FRFs.
    real(wp), parameter :: GN_TOL = 1.0e-4_wp, LU_SPEEDUP = 10.0_wp, GN_WORTH_MIN = 12.0_wp
    integer(ip), parameter :: GN_MINIT = 4
    !> GMRES iterations on a fresh single-precision LU before J is factorised in double
    integer(ip), parameter :: GS_MAXIT = 12
    !> Woodbury correction of a single LU: at most WB_PAIRS (mode, harmonic) pairs, those
    !> above WB_FLOOR times the most sensitive
    integer(ip), parameter :: WB_PAIRS = 96
    real(wp), parameter :: WB_FLOOR = 1.0e-4_wp

    !> J of a condensed system and the LU it holds, as fgmres sees them (jmul, lu_apply),
    !> pointing to the system for the length of one solve (gmres).
    type, extends(lin_operator) :: cond_operator
        type(hbm_condensed), pointer :: sys => null()
    contains
        procedure :: apply => op_apply
        procedure :: precond => op_precond
    end type cond_operator

contains

    module procedure cond_factor
        integer(ip) :: linfo, stat
        real(wp) :: t0
        logical :: single
        info = FRIROM_OK
        t0 = wtime()
        if (use_krylov(sys)) sys%jm = sys%jcur
        single = holds(sys)
        if (present(double)) single = single .and. .not. double
        call held_lu_factor(sys%held, sys%jm, single, linfo, stat)
        if (stat == 0 .and. single .and. linfo > 0) then
            ! a zero pivot in single precision (normal2d hooks of the paper mesh, ROM_I):
            ! the double LU of the same J, as cond_solve falls back to when GMRES stalls
            single = .false.
            sys%timers(N_DOUBLE) = sys%timers(N_DOUBLE) + 1.0_wp
            call held_lu_factor(sys%held, sys%jm, single, linfo, stat)
        end if
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'condensed: single LU')
            return
        end if
        if (single) then
            ! J (at the LU's frequency gj and contact state) applied matrix-free
            sys%jfree = .true.
            if (linfo == 0) call wb_build(sys)
        end if
        sys%timers(T_FACT) = sys%timers(T_FACT) + wtime() - t0
        sys%timers(N_FACT) = sys%timers(N_FACT) + 1
        sys%lu_fresh = linfo == 0
        sys%lu_any = linfo == 0
        if (linfo == 0 .and. allocated(sys%jy)) then
            sys%luy = sys%jy
            sys%lulam = sys%jlam
            if (allocated(sys%luw)) deallocate (sys%luw)
            allocate (sys%luw(max(nsl_of(sys), 1)))
            call hbm_sliders(sys, sys%luw)
        end if
        sys%gm_spent = 0.0_wp
        sys%refresh = .false.
        if (linfo > 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'condensed Jacobian: '// &
                            merge('sgetrf', 'dgetrf', single)//' zero pivot')
        else if (linfo < 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrf: illegal argument')
        end if
    end procedure cond_factor

    module procedure cond_solve
        integer(ip) :: linfo, j, its
        real(wp) :: t0
        logical :: ok, krylov, direct_gm
        info = FRIROM_OK
        t0 = wtime()
        krylov = use_krylov(this) .and. .not. this%lu_fresh
        direct_gm = this%gm_next
        this%gm_next = .false.
        j = 1
        if (direct_gm) then
            ! every column at once (one pass over the LU per iteration for all of them)
            call gmres(this, b, its, ok, GN_TOL, max(GN_MINIT, int(gm_cost(this)/3.0_wp, ip)))
            this%gm_spent = this%gm_spent + its
            this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
            if (.not. ok) then
                ! too slow: factorise this J, solve below
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                call modal_rmat(this)
                this%jfree = .false.
                this%refresh = .true.
                call cond_jacobian(this, info, errmsg)
                if (info /= 0) return
                t0 = wtime()
            end if
        else if (krylov) then
            ok = .true.
            do j = 1, size(b, 2)
                call gmres(this, b(:, j:j), its, ok)
                this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
                ! a preconditioner that needs many iterations is renewed at the next J
                if (its > GM_REFRESH) this%refresh = .true.
                if (ok) cycle
                ! too slow: factorise this J and solve the remaining columns directly
                this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
                call cond_factor(this, info, errmsg)
                if (info /= 0) return
                t0 = wtime()
                exit
            end do
        else
            ok = .false.
        end if
        if (ok) then
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            return
        end if
        if (this%held%single .and. .not. this%lu_fresh) then
            ! a chord step (Jacobian reused) with the LU of an older J, as a double one
            call chord_apply(this, b)
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            return
        else if (this%held%single) then
            ! the J of the LU (matrix-free) by GMRES on its single-precision LU
            call gmres(this, b(:, j:), its, ok, GM_TOL, GS_MAXIT)
            this%timers(N_KRYLOV) = this%timers(N_KRYLOV) + its
            this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
            if (ok) return
            ! J too ill-conditioned for single precision: the double LU of the J in jm
            this%timers(N_DOUBLE) = this%timers(N_DOUBLE) + 1.0_wp
            call cond_factor(this, info, errmsg, double=.true.)
            if (info /= 0) return
            t0 = wtime()
        end if
        call dgetrs('N', this%n, size(b, 2) - j + 1, this%jm, this%n, this%held%ipiv, b(:, j:), &
                    size(b, 1), linfo)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs failed')
    end procedure cond_solve

    !> GMRES iterations an LU of J is worth (direct mode, modal route) for n unknowns, nh
    !> harmonics, nnl unknowns per coefficient and nm modes: LU 2/3 n^3 flops at LU_SPEEDUP
    !> times the rate of an iteration's triangular solves (2 n^2) and matrix-free product
    !> (8 (nh+1) nnl nm: projection and back, complex).
    pure real(wp) function lu_worth(n, nh, nnl, nm)
        integer(ip), intent(in) :: n, nh, nnl, nm
        real(wp) :: rn
        rn = real(n, wp)
        lu_worth = (2.0_wp/3.0_wp*rn**3/LU_SPEEDUP)/(2.0_wp*rn**2 + 8.0_wp* &
                   real(nh + 1, wp)*real(nnl, wp)*real(nm, wp))
    end function lu_worth

    module procedure gm_cost
        if (sys%gm_worth <= 0.0_wp) sys%gm_worth = lu_worth(sys%n, sys%nh, sys%nnl, &
                                                           size(sys%g, 1))
        gm_cost = sys%gm_worth
    end procedure gm_cost

    module procedure cond_lu_holds
        hold = lu_worth(nnl*(2*nh + 1), nh, nnl, nm) >= GN_WORTH_MIN
    end procedure cond_lu_holds

    module procedure holds
        holds = .false.
        if (.not. sys%modal .or. use_krylov(sys) .or. allocated(sys%sel)) return
        holds = lu_worth(sys%n, sys%nh, sys%nnl, size(sys%g, 1)) >= GN_WORTH_MIN
    end procedure holds

    module procedure hbm_lu_forget
        select type (sys => sysc)
        type is (hbm_condensed)
            sys%lu_any = .false.
            sys%lu_fresh = .false.
            sys%gm_spent = 0.0_wp
            sys%gm_next = .false.
            sys%refresh = .false.
            sys%held%wb%ok = .false.
        end select
    end procedure hbm_lu_forget

    module procedure hbm_lu_state_size
        nv = 1
        select type (sys => sysc)
        type is (hbm_condensed)
            nv = 8 + sys%n + nsl_of(sys)
        end select
    end procedure hbm_lu_state_size

    module procedure hbm_lu_state
        integer(ip) :: n, nw
        v = 0.0_wp
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. (sys%lu_any .and. allocated(sys%luy))) return
            n = sys%n
            nw = nsl_of(sys)
            v(1:8) = [1.0_wp, merge(1.0_wp, 0.0_wp, sys%held%single), sys%lulam, &
                      sys%gm_spent, merge(1.0_wp, 0.0_wp, sys%refresh), 1.0_wp, &
                      merge(1.0_wp, 0.0_wp, sys%lu_fresh), merge(1.0_wp, 0.0_wp, sys%gm_next)]
            v(9:8 + n) = sys%luy
            if (nw > 0) v(9 + n:8 + n + nw) = sys%luw(1:nw)
        end select
    end procedure hbm_lu_state

    module procedure hbm_lu_rebuild
        real(wp), allocatable :: r(:), rlam(:), wnow(:)
        real(wp) :: rref
        integer(ip) :: n, nw
        info = FRIROM_OK
        call hbm_lu_forget(sysc)
        select type (sys => sysc)
        type is (hbm_condensed)
            n = sys%n
            nw = nsl_of(sys)
            if (size(v) /= 8 + n + nw .or. .not. all(abs(v) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'held LU state: '// &
                                'hbm_lu_state_size finite values of this system expected')
                return
            end if
            if (.not. (all(v(1:8:1) == 0.0_wp .or. v(1:8:1) == 1.0_wp .or. &
                           [.false., .false., .true., .true., .false., .false., .false., &
                            .false.]) .and. v(4) >= 0.0_wp)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'held LU state: flags '// &
                                '(entries 1, 2, 5-8) 0 or 1 and a count (4) >= 0 expected')
                return
            end if
            if (v(1) == 0.0_wp) return
            if (v(2) == 1.0_wp .and. .not. holds(sys)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'held LU state: a '// &
                                'single-precision LU, which this system does not hold')
                return
            end if
            allocate (r(n), rlam(n), wnow(max(nw, 1)))
            call hbm_sliders(sys, wnow)
            call hbm_set_sliders(sys, v(9 + n:8 + n + nw))
            call sys%eval(v(9:8 + n), v(3), r, rref, .true., rlam, info, errmsg)
            if (info == 0 .and. v(2) == 0.0_wp .and. sys%held%single) then
                ! the double LU a single one gave way to (cond_solve)
                call cond_factor(sys, info, errmsg, double=.true.)
            end if
            call hbm_set_sliders(sys, wnow(1:nw))
            if (info /= 0) return
            ! lu_fresh and gm_next (v(7:8)) are not taken: the next evaluation with a
            ! Jacobian sets both, as it does in the run that wrote the state
            sys%gm_spent = v(4)
            sys%refresh = v(5) /= 0.0_wp
            sys%lu_any = v(6) /= 0.0_wp
            sys%lu_fresh = .false.
            sys%gm_next = .false.
        end select
    end procedure hbm_lu_rebuild

    !> Sliders of a system's contact groups (hbm_sliders' layout).
    integer(ip) function nsl_of(sys)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), allocatable :: k0(:)
        k0 = hbm_slider_offsets(sys)
        nsl_of = k0(size(k0))
    end function nsl_of

    !> y = J x: the assembled jcur, or matrix-free (jfree: modal route) as
    !> x + R_h G^T J_loc G x at the Jacobian's frequency, element by element and mode by
    !> mode (R_h = A diag(g) A^H never formed).
    subroutine jmul(sys, x, y)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: x(:)
        real(wp), intent(out) :: y(:)
        real(wp), allocatable :: xv(:, :), f(:, :), y2(:, :), vr(:, :)
        complex(wp), allocatable :: fc(:), v(:, :), b1(:, :)
        integer(ip) :: n, nu, nc, h, nm
        n = sys%n
        if (.not. sys%jfree) then
            call dgemm('N', 'N', n, 1, n, 1.0_wp, sys%jcur, n, x, n, 0.0_wp, y, n)
            return
        end if
        nu = sys%nnl
        nc = sys%nc
        xv = reshape(x, [nu, nc])
        allocate (f(nu, nc), y2(nu, nc), fc(nu), v(size(sys%gj, 1), 1), b1(nu, 1))
        call kmul(sys, xv, f, .false.)
        if (allocated(sys%phr)) then
            ! real modes, the same for every harmonic: all harmonics in two products (the
            ! modes are read twice, not twice per harmonic); A^T commutes with harm_col
            nm = size(sys%gj, 1)
            allocate (vr(nm, nc))
            call dgemm('T', 'N', nm, nc, nu, 1.0_wp, sys%phr, size(sys%phr, 1), f, nu, &
                       0.0_wp, vr, nm)
            do h = 0, sys%nh
                call harm_set(vr, h, sys%gj(:, h)*harm_col(vr, h))
            end do
            call dgemm('N', 'N', nu, nc, nm, 1.0_wp, sys%phr, size(sys%phr, 1), vr, nm, &
                       0.0_wp, y2, nu)
        else
            do h = 0, sys%nh
                fc = harm_col(f, h)
                call modal_project(sys, h, fc, v(:, 1))
                v(:, 1) = sys%gj(:, h)*v(:, 1)
                call modal_apply(sys, h, 1, nu, v, b1)
                call harm_set(y2, h, b1(:, 1))
            end do
        end if
        y = x + reshape(y2, [n])
    end subroutine jmul

    !> f = K x (trans: K^T x) for K = dF_c/dU = G^T J_e G element by element, x and f
    !> (nu, nc) by harmonic coefficient.
    subroutine kmul(sys, xv, f, trans)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: xv(:, :)
        real(wp), intent(out) :: f(:, :)
        logical, intent(in) :: trans
        real(wp), allocatable :: xl(:, :), fl(:)
        integer(ip) :: nc, g, e, d, r, k
        nc = sys%nc
        f = 0.0_wp
        do g = 1, size(sys%cs%grp)
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                allocate (xl(nc, gr%ndir), fl(nc*gr%ndir))
                do e = 1, gr%ne
                    do d = 1, gr%ndir
                        r = gr%row0 + (e - 1)*gr%ndir + d
                        xl(:, d) = 0.0_wp
                        do k = gg%p(r), gg%p(r + 1) - 1
                            xl(:, d) = xl(:, d) + gg%x(k)*xv(gg%i(k), :)
                        end do
                    end do
                    if (trans) then
                        fl = matmul(reshape(xl, [nc*gr%ndir]), gr%jac(:, :, e))
                    else
                        fl = matmul(gr%jac(:, :, e), reshape(xl, [nc*gr%ndir]))
                    end if
                    do d = 1, gr%ndir
                        r = gr%row0 + (e - 1)*gr%ndir + d
                        do k = gg%p(r), gg%p(r + 1) - 1
                            f(gg%i(k), :) = f(gg%i(k), :) + gg%x(k)*fl(1 + nc*(d - 1):nc*d)
                        end do
                    end do
                end do
                deallocate (xl, fl)
            end associate
        end do
    end subroutine kmul

    !> The Woodbury data of a fresh single LU (real modes): the WB_PAIRS (mode, harmonic
    !> >= 1) pairs whose factor moves most with w at the LU's w (|dg| |phi|^2), their U
    !> (their contact rows on the harmonic's cos and sin rows) and V = U^T K (K = dF_c/dU
    !> at the LU), then woodbury_finish. Only a preconditioner.
    subroutine wb_build(sys)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), allocatable :: sens(:, :), nphi(:), xv(:, :), f(:, :)
        integer(ip) :: nu, nc, nm, np, k, h, r, c, q, loc(2), n, stat
        real(wp) :: smax
        call woodbury_reset(sys%held, sys%wj)
        ! dg is that of the receptances' w, the J's (each eval with jac precedes its solve)
        if (.not. allocated(sys%phr) .or. sys%nh < 1 .or. sys%w_cache /= sys%wj) return
        nu = sys%nnl
        nc = sys%nc
        n = sys%n
        nm = size(sys%gj, 1)
        allocate (sens(nm, sys%nh), nphi(nm))
        do r = 1, nm
            nphi(r) = sum(sys%phr(1:nu, r)**2)
        end do
        do h = 1, sys%nh
            sens(:, h) = abs(sys%dg(:, h))*sys%wj*nphi
        end do
        smax = maxval(sens)
        ! an undamped mode at resonance: no finite scale to rank the pairs by
        if (.not. (smax > 0.0_wp .and. smax <= huge(smax))) return
        np = min(WB_PAIRS, nm*sys%nh)
        if (allocated(sys%wbm)) deallocate (sys%wbm, sys%wbh, sys%wbg)
        allocate (sys%wbm(np), sys%wbh(np), sys%wbg(np), stat=stat)
        if (stat /= 0) return
        k = 0
        do while (k < np)
            loc = maxloc(sens)
            if (.not. sens(loc(1), loc(2)) > WB_FLOOR*smax) exit
            k = k + 1
            sys%wbm(k) = loc(1)
            sys%wbh(k) = loc(2)
            sys%wbg(k) = sys%gj(loc(1), loc(2))
            sens(loc(1), loc(2)) = -1.0_wp
        end do
        np = k
        if (np == 0) return
        call woodbury_alloc(sys%held, n, 2*np, stat)
        if (stat == 0) allocate (xv(nu, nc), f(nu, nc), stat=stat)
        if (stat /= 0) return     ! no correction: the LU alone preconditions
        sys%held%wb%w = 0.0_wp
        do k = 1, np
            do q = 0, 1
                c = 2*sys%wbh(k) + q
                sys%held%wb%w(nu*(c - 1) + 1:nu*c, 2*k - 1 + q) = sys%phr(1:nu, sys%wbm(k))
                ! row of V: (K^T U_k)^T
                xv = 0.0_wp
                xv(:, c) = sys%phr(1:nu, sys%wbm(k))
                call kmul(sys, xv, f, .true.)
                sys%held%wb%v(2*k - 1 + q, :) = reshape(f, [n])
            end do
        end do
        call woodbury_finish(sys%held)
    end subroutine wb_build

    !> The Woodbury correction's small LU for the factors at the J's w (woodbury_prepare).
    subroutine wb_prepare(sys)
        type(hbm_condensed), intent(inout) :: sys
        if (.not. sys%held%wb%ok) return
        call woodbury_prepare(sys%held, sys%wj, wb_change(sys))
    end subroutine wb_prepare

    !> The change of the Woodbury pairs' factors since the LU, at the J's w: gj - wbg.
    pure function wb_change(sys) result(d)
        type(hbm_condensed), intent(in) :: sys
        complex(wp) :: d(size(sys%held%wb%s, 1)/2)
        integer(ip) :: k
        do k = 1, size(d)
            d(k) = sys%gj(sys%wbm(k), sys%wbh(k)) - sys%wbg(k)
        end do
    end function wb_change

    !> w := M^-1 w for the LU held (held_lu_apply: single-precision factors, or the
    !> double ones in jm), all columns at once, with the Woodbury correction for the J's
    !> w when it is prepared.
    subroutine lu_apply(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: w(:, :)
        if (sys%held%wb%ok) then
            call held_lu_apply(sys%held, sys%jm, w, sys%wj, wb_change(sys))
        else
            call held_lu_apply(sys%held, sys%jm, w, sys%wj)
        end if
    end subroutine lu_apply

    !> A chord step's w := M^-1 w with the LU held, its Woodbury correction taken at the
    !> frequency of the last evaluation (w_cache: the iterate's) rather than the J's: at
    !> a contact state the LU's, the change of J since is that of the modal factors.
    subroutine chord_apply(sys, w)
        type(hbm_condensed), intent(inout) :: sys
        real(wp), intent(inout) :: w(:, :)
        complex(wp), allocatable :: d(:)
        integer(ip) :: k
        if (.not. (sys%held%wb%ok .and. allocated(sys%g))) then
            call lu_apply(sys, w)
            return
        end if
        allocate (d(size(sys%held%wb%s, 1)/2))
        do k = 1, size(d)
            d(k) = sys%g(sys%wbm(k), sys%wbh(k)) - sys%wbg(k)
        end do
        call woodbury_prepare(sys%held, sys%w_cache, d)
        call held_lu_apply(sys%held, sys%jm, w, sys%w_cache, d)
    end subroutine chord_apply

    !> b := J^-1 b, column by column, by restarted flexible GMRES (fgmres) on jcur (or J
    !> matrix-free), right-preconditioned by the LU held (from an earlier J or in single
    !> precision), to a residual of GM_TOL |b| (or tol |b|). its: the iterations summed
    !> over the columns; ok false (b unchanged) when a column needs more than GM_MAXIT
    !> (or maxit).
    subroutine gmres(sys, b, its, ok, tol, maxit)
        type(hbm_condensed), intent(inout), target :: sys
        real(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: its
        logical, intent(out) :: ok
        real(wp), intent(in), optional :: tol
        integer(ip), intent(in), optional :: maxit
        type(cond_operator) :: op
        real(wp) :: rtol
        integer(ip) :: itmax
        rtol = GM_TOL
        if (present(tol)) rtol = tol
        itmax = GM_MAXIT
        if (present(maxit)) itmax = maxit
        call wb_prepare(sys)
        op%sys => sys
        call fgmres(op, b, rtol, itmax, sys%gmw, its, ok)
    end subroutine gmres

    !> y = J x (jmul).
    subroutine op_apply(this, x, y)
        class(cond_operator), intent(inout) :: this
        real(wp), intent(in) :: x(:)
        real(wp), intent(out) :: y(:)
        call jmul(this%sys, x, y)
    end subroutine op_apply

    !> w := M^-1 w by the LU held (lu_apply).
    subroutine op_precond(this, w)
        class(cond_operator), intent(inout) :: this
        real(wp), intent(inout) :: w(:, :)
        call lu_apply(this%sys, w)
    end subroutine op_precond
end submodule frirom_hbm_factor
