! One of the two sources f2py reads (frirom_f2py_run.f90 holds the run object's calls).
! Plain subroutines with explicit-shape arrays and real(8) / integer(4) dummies (f2py would
! map a real(wp) from another module to C float). Each one
! unpacks its arguments, calls the library and returns `info` plus the library's message.
! Derived types never cross this file. Python types no number of this boundary: option
! slots, start modes, timer slots and status codes are read by name (int_constant,
! real_constant) when frirom is imported.

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
                    max_periods, f, jac, periods, states, slider, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_aft, only: aft_plan, aft_plan_create, aft_plan_destroy, &
                          frirom_aft_eval => aft_eval
    implicit none
    integer(4), intent(in) :: law, nharm, nsamp, ndir, npar, nsl, ne, nj, nje, max_periods
    real(8), intent(in) :: x(2*nharm + 1, ndir, ne), params(npar, ne), w0(nsl, ne), tol
    real(8), intent(out) :: f(2*nharm + 1, ndir, ne), jac(nj, nj, nje)
    integer(4), intent(out) :: periods(ne)
    real(8), intent(out) :: states(3, ne), slider(nsl, ne)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(aft_plan) :: plan
    integer(ip) :: st, per(ne)
    msg = ''
    f = 0.0d0
    periods = 0
    states = 0.0d0
    slider = 0.0d0
    call aft_plan_create(plan, int(nharm, ip), int(nsamp, ip), st, msg)
    if (st == 0) then
        if (nje > 0) then
            call frirom_aft_eval(plan, int(law, ip), x, params, w0, f, st, msg, jac=jac, &
                                 periods=per, states=states, tol=real(tol, wp), &
                                 max_periods=int(max_periods, ip), index_base=0_ip, &
                                 slider=slider)
        else
            call frirom_aft_eval(plan, int(law, ip), x, params, w0, f, st, msg, periods=per, &
                                 states=states, tol=real(tol, wp), &
                                 max_periods=int(max_periods, ip), index_base=0_ip, &
                                 slider=slider)
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

!> Reverse Cuthill-McKee order of a symmetric pattern (CSR, 1-based): perm(k) = node at k.
subroutine hbm_rcm(n, nnz, indptr, indices, perm, info, msg)
    use frirom_kinds, only: ip
    use frirom_banded, only: rcm_order
    implicit none
    integer(4), intent(in) :: n, nnz
    integer(4), intent(in) :: indptr(n + 1), indices(nnz)
    integer(4), intent(out) :: perm(n)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: linfo
    msg = ''
    call rcm_order(indptr, indices, perm, linfo, msg)
    info = linfo
end subroutine hbm_rcm

!> Whether a condensed modal system in direct mode of nnl unknowns per harmonic
!> coefficient, nh harmonics and nmodes modes holds an LU as GMRES preconditioner of later
!> Jacobians (hold = 1; frirom_hbm cond_lu_holds): a run then keeps it from one
!> corrector to the next, and forgets it at every run_advance segment (exact resume).
subroutine hbm_lu_holds(nh, nnl, nmodes, hold)
    use frirom_kinds, only: ip
    use frirom_hbm, only: cond_lu_holds
    implicit none
    integer(4), intent(in) :: nh, nnl, nmodes
    integer(4), intent(out) :: hold
    hold = merge(1, 0, cond_lu_holds(int(nh, ip), int(nnl, ip), int(nmodes, ip)))
end subroutine hbm_lu_holds

!> Whether the condensed unknowns are the contact coordinates (tcontact = 1) for a
!> coordinates choice (COORD_AUTO 0, COORD_DOFS 1, COORD_CONTACT 2), nrows contact rows,
!> nnl contact DoFs, stability and a selection (1: yes): frirom_run run_contact_coords.
subroutine contact_coords(coordinates, nrows, nnl, stability, selected, tcontact)
    use frirom_kinds, only: ip
    use frirom_run, only: run_contact_coords
    implicit none
    integer(4), intent(in) :: coordinates, nrows, nnl, stability, selected
    integer(4), intent(out) :: tcontact
    tcontact = merge(1, 0, run_contact_coords(int(coordinates, ip), int(nrows, ip), &
                                              int(nnl, ip), stability == 1, selected == 1))
end subroutine contact_coords

!> The solver settings' defaults (frirom_run run_settings, the one place they are
!> written): iset integers and rset reals in the order of `names` (blank-separated).
subroutine settings_defaults(niset, iset, nrset, rset, names)
    use frirom_kinds, only: ip
    use frirom_run, only: run_settings, settings_pack, run_settings_names, N_ISET, N_RSET
    implicit none
    integer(4), intent(in) :: niset, nrset
    integer(4), intent(out) :: iset(niset)
    real(8), intent(out) :: rset(nrset)
    character(len=160), intent(out) :: names
    type(run_settings) :: s
    integer(ip) :: iv(N_ISET)
    real(8) :: rv(N_RSET)
    call settings_pack(s, iv, rv)
    iset = 0
    rset = 0.0d0
    iset(1:min(niset, N_ISET)) = int(iv(1:min(niset, N_ISET)), 4)
    rset(1:min(nrset, N_RSET)) = rv(1:min(nrset, N_RSET))
    names = run_settings_names()
end subroutine settings_defaults

!> The default AFT samples per period for nh harmonics (frirom_run's rule, the one place
!> it is written; frirom.harmonics.default_samples reads it).
subroutine default_samples(nh, ns)
    use frirom_kinds, only: ip
    use frirom_run, only: run_default_samples
    implicit none
    integer(4), intent(in) :: nh
    integer(4), intent(out) :: ns
    ns = int(run_default_samples(int(nh, ip)), 4)
end subroutine default_samples

!> Value of a named integer constant of this interface, so that Python reads slots, modes
!> and codes from Fortran instead of typing their numbers: RUN_* (formulations, parameter
!> kinds, start kinds, stop reasons, solve kinds of frirom_run), ADVISE_* (advice bits),
!> N_ISET, N_RSET (settings layout), T_*, N_EVAL, N_FACT, N_KRYLOV, N_DOUBLE, N_TIMERS
!> (timings slots, frirom_hbm), HILL_DENSE_MAX and the FRIROM_* status codes.
!> An unknown name returns info = FRIROM_ERR_PARAM.
subroutine int_constant(name, value, info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_PARAM, frirom_status_code, set_status
    use frirom_run, only: RUN_CONDENSED, RUN_BANDED, RUN_FREQUENCY, RUN_LOAD, RUN_MODE, &
                          RUN_START_COLD, RUN_START_POINT, RUN_START_RESUME, RUN_GOING, &
                          RUN_DONE, RUN_MAX_POINTS, RUN_LEFT_RANGE, RUN_FAILED, RUN_STALLED, &
                          RUN_SOLVE_FIXED, RUN_SOLVE_STEP, ADVISE_TOL_STALL, ADVISE_MAX_ITER, &
                          ADVISE_DS_MIN, ADVISE_SAMPLES, N_ISET, N_RSET, COORD_AUTO, COORD_DOFS, &
                          COORD_CONTACT
    use frirom_hbm, only: T_AFT, T_ASM, T_FACT, T_SOLVE, T_REC, N_EVAL, N_FACT, N_KRYLOV, &
                          N_DOUBLE, N_TIMERS, HILL_DENSE_MAX, T_HILL
    implicit none
    character(len=*), intent(in) :: name
    integer(4), intent(out) :: value
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: linfo
    msg = ''
    info = 0
    select case (name)
    case ('RUN_CONDENSED')
        value = RUN_CONDENSED
    case ('RUN_BANDED')
        value = RUN_BANDED
    case ('RUN_FREQUENCY')
        value = RUN_FREQUENCY
    case ('RUN_LOAD')
        value = RUN_LOAD
    case ('RUN_MODE')
        value = RUN_MODE
    case ('RUN_START_COLD')
        value = RUN_START_COLD
    case ('RUN_START_POINT')
        value = RUN_START_POINT
    case ('RUN_START_RESUME')
        value = RUN_START_RESUME
    case ('RUN_GOING')
        value = RUN_GOING
    case ('RUN_DONE')
        value = RUN_DONE
    case ('RUN_MAX_POINTS')
        value = RUN_MAX_POINTS
    case ('RUN_LEFT_RANGE')
        value = RUN_LEFT_RANGE
    case ('RUN_FAILED')
        value = RUN_FAILED
    case ('RUN_STALLED')
        value = RUN_STALLED
    case ('RUN_SOLVE_FIXED')
        value = RUN_SOLVE_FIXED
    case ('RUN_SOLVE_STEP')
        value = RUN_SOLVE_STEP
    case ('ADVISE_TOL_STALL')
        value = ADVISE_TOL_STALL
    case ('ADVISE_MAX_ITER')
        value = ADVISE_MAX_ITER
    case ('ADVISE_DS_MIN')
        value = ADVISE_DS_MIN
    case ('ADVISE_SAMPLES')
        value = ADVISE_SAMPLES
    case ('COORD_AUTO')
        value = COORD_AUTO
    case ('COORD_DOFS')
        value = COORD_DOFS
    case ('COORD_CONTACT')
        value = COORD_CONTACT
    case ('N_ISET')
        value = N_ISET
    case ('N_RSET')
        value = N_RSET
    case ('HILL_DENSE_MAX')
        value = HILL_DENSE_MAX
    case ('T_AFT')
        value = T_AFT
    case ('T_ASM')
        value = T_ASM
    case ('T_FACT')
        value = T_FACT
    case ('T_SOLVE')
        value = T_SOLVE
    case ('T_REC')
        value = T_REC
    case ('N_EVAL')
        value = N_EVAL
    case ('N_FACT')
        value = N_FACT
    case ('N_KRYLOV')
        value = N_KRYLOV
    case ('N_DOUBLE')
        value = N_DOUBLE
    case ('T_HILL')
        value = T_HILL
    case ('N_TIMERS')
        value = N_TIMERS
    case default
        value = frirom_status_code(name)
        if (value < 0) then
            call set_status(linfo, FRIROM_ERR_PARAM, msg, 'int_constant: no constant named '// &
                            trim(name))
            info = linfo
        end if
    end select
end subroutine int_constant

!> Value of a named real constant of this interface: YSCALE_RELATIVE (frirom_newton), the
!> yscale of a first solve whose update test is purely relative. Unknown: FRIROM_ERR_PARAM.
subroutine real_constant(name, value, info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_PARAM, set_status
    use frirom_newton, only: YSCALE_RELATIVE
    implicit none
    character(len=*), intent(in) :: name
    real(8), intent(out) :: value
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: linfo
    msg = ''
    info = 0
    value = 0.0d0
    if (name == 'YSCALE_RELATIVE') then
        value = YSCALE_RELATIVE
    else
        call set_status(linfo, FRIROM_ERR_PARAM, msg, 'real_constant: no constant named '// &
                        trim(name))
        info = linfo
    end if
end subroutine real_constant

!> GFLOP/s of the dgemm the library links (reps products of n x n matrices), for benchmarks
!> that compare factorisation rates with the BLAS actually used.
subroutine hbm_dgemm_rate(n, reps, gflops)
    use frirom_lapack, only: dgemm
    implicit none
    integer(4), intent(in) :: n, reps
    real(8), intent(out) :: gflops
    real(8), allocatable :: a(:, :), b(:, :), c(:, :)
    integer(8) :: c0, c1, rate
    integer(4) :: k
    allocate (a(n, n), b(n, n), c(n, n))
    call random_number(a)
    call random_number(b)
    call dgemm('N', 'N', n, n, n, 1.0d0, a, n, b, n, 0.0d0, c, n)
    call system_clock(c0, rate)
    do k = 1, reps
        call dgemm('N', 'N', n, n, n, 1.0d0, a, n, b, n, 0.0d0, c, n)
    end do
    call system_clock(c1)
    gflops = 2.0d0*real(n, 8)**3*reps/max(real(c1 - c0, 8)/real(rate, 8), 1.0d-9)/1.0d9
end subroutine hbm_dgemm_rate

! ---- reduction: eigen-solves, Craig-Bampton, interface reduction -------------------

!> Eigenpairs of K phi = lambda M phi nearest sigma (ARPACK shift-invert, MUMPS factor) and
!! static solves K x = rhs with the same (or, when sigma /= 0, a second) factor of K.
!! K and M as upper-triangle coordinates (1-based); M also as full CSR for the products.
!! nev = 0 skips the eigen-solve, nrhs = 0 the static solves.
subroutine eigen_shift_invert(n, nk, krow, kcol, kval, nm, mrow, mcol, mval, mptr, nmc, &
                              mind, mvalc, sigma, nev, lam, phi, nrhs, rhs, ncv, tol, &
                              maxiter, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_eigen, only: eigen_work, eigen_factor, eigen_solve, eigen_modes, eigen_destroy
    implicit none
    integer(4), intent(in) :: n, nk, nm, nmc, nev, nrhs, ncv, maxiter
    integer(4), intent(in) :: krow(nk), kcol(nk), mrow(nm), mcol(nm), mptr(n + 1), mind(nmc)
    real(8), intent(in) :: kval(nk), mval(nm), mvalc(nmc), sigma, tol
    real(8), intent(out) :: lam(nev), phi(n, nev)
    real(8), intent(inout) :: rhs(n, nrhs)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(eigen_work) :: work
    integer(ip) :: st

    msg = ''
    info = 0
    call eigen_factor(work, int(n, ip), krow, kcol, kval, mrow, mcol, mval, real(sigma, wp), &
                      st, msg)
    if (st == 0 .and. nev > 0) then
        call eigen_modes(work, mptr, mind, mvalc, int(nev, ip), lam, phi, st, msg, &
                         ncv=int(ncv, ip), tol=real(tol, wp), maxiter=int(maxiter, ip))
    end if
    if (st == 0 .and. nrhs > 0) then
        if (sigma /= 0.0d0) then
            call eigen_factor(work, int(n, ip), krow, kcol, kval, mrow, mcol, mval, 0.0_wp, &
                              st, msg)
        end if
        if (st == 0) call eigen_solve(work, rhs, st, msg)
    end if
    call eigen_destroy(work)
    info = int(st, 4)
end subroutine eigen_shift_invert

! ---- the contact-law table -----------------------------------------------------------

!> frirom_aft's contact-law table for one code: number of directions, parameters and
!> slider components, and the name (zeros and a blank name for an unknown code); nlaw:
!> the number of laws, whose codes are 1..nlaw. Python checks its table against this.
subroutine law_info(law, ndir, npar, nslider, name, nlaw)
    use frirom_kinds, only: ip
    use frirom_aft, only: LAW_CODES, frirom_law_info => law_info
    implicit none
    integer(4), intent(in) :: law
    integer(4), intent(out) :: ndir, npar, nslider, nlaw
    character(len=16), intent(out) :: name
    integer(ip) :: nd, np, ns
    call frirom_law_info(int(law, ip), nd, np, ns, name)
    ndir = int(nd, 4)
    npar = int(np, 4)
    nslider = int(ns, 4)
    nlaw = int(size(LAW_CODES), 4)
end subroutine law_info

!> The stuck stiffness ks (ndir, ne) [N/m] of ne elements of one law (frirom_aft
!> law_stuck_stiffness): what a body held only by its contacts borrows (frirom_hbm_free).
subroutine stuck_stiffness(law, npar, ndir, ne, params, ks)
    use frirom_kinds, only: ip
    use frirom_aft, only: law_stuck_stiffness
    implicit none
    integer(4), intent(in) :: law, npar, ndir, ne
    real(8), intent(in) :: params(npar, ne)
    real(8), intent(out) :: ks(ndir, ne)
    integer :: e
    do e = 1, ne
        call law_stuck_stiffness(int(law, ip), params(:, e), ks(:, e))
    end do
end subroutine stuck_stiffness

! ---- peak amplitude and modal damping --------------------------------------------------

!> max over one period of |x(t)| of each of n real trigonometric polynomials, exactly
!> (frirom_peak): x (nc, n), one [a0, a1, b1, ..., aH, bH] per column (a C-ordered
!> (n, nc) array); amp, t (n), t in rad. A non-finite column gives NaN and info
!> FRIROM_ERR_NONFINITE, the others are still computed.
subroutine peak_amplitudes(n, nc, x, amp, t, info, msg)
    use frirom_kinds, only: ip
    use frirom_peak, only: frirom_peak_amplitudes => peak_amplitudes
    implicit none
    integer(4), intent(in) :: n, nc
    real(8), intent(in) :: x(nc, n)
    real(8), intent(out) :: amp(n), t(n)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: st
    msg = ''
    call frirom_peak_amplitudes(x, amp, t, st, msg)
    info = int(st, 4)
end subroutine peak_amplitudes

!> Modal damping C = M Phi diag(2 zeta omega) Phi^T M of the lowest nm modes of dense
!> real symmetric K, M (n, n) (frirom_damping; lower triangles read); omega (nm) rad/s.
subroutine modal_damping(n, nm, k, m, zeta, c, omega, info, msg)
    use frirom_kinds, only: ip
    use frirom_damping, only: frirom_modal_damping => modal_damping
    implicit none
    integer(4), intent(in) :: n, nm
    real(8), intent(in) :: k(n, n), m(n, n), zeta(nm)
    real(8), intent(out) :: c(n, n), omega(nm)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: st
    msg = ''
    call frirom_modal_damping(k, m, zeta, c, omega, st, msg)
    info = int(st, 4)
end subroutine modal_damping

!> modal_damping of dense complex Hermitian K, M (n, n): C = M Phi diag(2 zeta omega) Phi^H M.
subroutine modal_damping_hermitian(n, nm, k, m, zeta, c, omega, info, msg)
    use frirom_kinds, only: ip
    use frirom_damping, only: frirom_modal_damping => modal_damping
    implicit none
    integer(4), intent(in) :: n, nm
    complex(8), intent(in) :: k(n, n), m(n, n)
    real(8), intent(in) :: zeta(nm)
    complex(8), intent(out) :: c(n, n)
    real(8), intent(out) :: omega(nm)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: st
    msg = ''
    call frirom_modal_damping(k, m, zeta, c, omega, st, msg)
    info = int(st, 4)
end subroutine modal_damping_hermitian
