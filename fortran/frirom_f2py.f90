! The only source f2py reads. Plain subroutines with explicit-shape arrays and real(8) /
! integer(4) dummies (f2py would map a real(wp) from another module to C float). Each one
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

!> Harmonic balance solve and pseudo-arc-length continuation (frirom_hbm hbm_run).
!> formulation: 'condensed' or 'banded'; lam_kind: 'frequency' (lam = omega) or 'load'
!> (lam scales fe1 at omega_fix). K, M, C: CSR, 1-based, ndof x ndof, symmetric.
!> perm: RCM order of the DoFs. nl: nonlinear DoFs (condensed); tcontact: condensed
!> unknowns in contact coordinates (G x) instead. fe0, fe1: real harmonic
!> excitation (ndof, 2H+1) (frequency: fe0; load: fe0 + lam fe1).
!> ginfo(3, ngroup): law, n_elem, n_dir; G rows group by group, element, direction (CSR over
!> the full DoFs); params (npar, ne) and w0 (nslider, ne) per group, concatenated.
!> start_mode (HBM_START_*): solve at lam0 from y0 then continue, resume from (y0, lam0,
!> tan0), or solve at lam0 only. ropt, iopt: Newton and continuation settings by slot
!> (RCONT_*, ICONT_* of frirom_newton; Python reads all of these names with int_constant).
!> Outputs: npts points; timings(T_*): AFT, assembly, factorisation, solve, receptances (s),
!> residual evaluations, factorisations, GMRES iterations, double-precision fall-back
!> factorisations (N_DOUBLE); timings(N_TIMERS): total (s).
subroutine hbm_continue(formulation, lam_kind, nh, nsamp, ndof, nnzk, kp, ki, kx, nnzm, mp, &
                        mi, mx, nnzc, cp, ci, cx, perm, nnl, nl, fe0, fe1, omega_fix, ngroup, &
                        ginfo, nrows, nnzg, gp, gi, gx, npart, params, nw0, w0, nout, outdofs, &
                        nmodes, phi, wmodes, zmodes, hmodes, psi, wharm, zharm, ny, y0, lam0, &
                        tan0, start_mode, nropt, ropt, niopt, iopt, stability, history, &
                        maxpts, netot, ntim, ys, lams, tans, iters, xo, states, hill_re, &
                        sliders, yscales, npts, finished, ds_out, timings, info, msg, &
                        tcontact, krylov, sparse, nlu, lu, lupiv, lustate, selected, keep, pair, &
                        leak, orbtol, orbinfo, orbmap)
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, set_status
    use frirom_newton, only: cont_options, cont_options_from, N_RCONT, N_ICONT, RCONT_DS, &
                             RCONT_LAM_LO
    use frirom_hbm, only: hbm_system, hbm_condensed, hbm_full, hbm_setup, hbm_set_modes, &
                          hbm_set_modes_harmonic, hbm_run, hbm_lu_import, hbm_lu_export, &
                          hbm_set_selection, hbm_sel_expand, hbm_sel_reduce, hbm_set_orbits, &
                          HBM_FREQUENCY, HBM_LOAD, N_TIMERS
    implicit none
    character(len=*), intent(in) :: formulation  !! 'condensed' (Eq. 5-9) or 'banded'
    character(len=*), intent(in) :: lam_kind     !! the parameter lam: 'frequency' or 'load'
    integer(4), intent(in) :: nh, nsamp, ndof, nnzk, nnzm, nnzc
    integer(4), intent(in) :: kp(ndof + 1), ki(nnzk), mp(ndof + 1), mi(nnzm), cp(ndof + 1), &
                              ci(nnzc)
    real(8), intent(in) :: kx(nnzk), mx(nnzm), cx(nnzc)
    integer(4), intent(in) :: perm(ndof), nnl, nl(nnl)
    !> condensed: 1 = unknowns in contact coordinates u = G x (nrows per harmonic), 0 = the
    !> nl DoFs (nnl per harmonic)
    integer(4), intent(in) :: tcontact
    !> condensed: 1 = linear solves by GMRES preconditioned by an older LU, 0 or -1 = a
    !> new LU for every Jacobian
    integer(4), intent(in) :: krylov
    integer(4), intent(in) :: sparse   !! condensed: 1 = receptances by sparse LU (MUMPS)
    real(8), intent(in) :: fe0(ndof, 2*nh + 1), fe1(ndof, 2*nh + 1)
    real(8), intent(in) :: omega_fix     !! rad/s, the frequency of a load continuation
    integer(4), intent(in) :: ngroup, ginfo(3, ngroup), nrows, nnzg, gp(nrows + 1), gi(nnzg)
    real(8), intent(in) :: gx(nnzg)
    integer(4), intent(in) :: npart, nw0
    real(8), intent(in) :: params(npart), w0(nw0)
    integer(4), intent(in) :: nout, outdofs(nout)
    integer(4), intent(in) :: nmodes       !! > 0: condensed receptances by modal superposition
    real(8), intent(in) :: phi(ndof, max(nmodes, 1)), wmodes(max(nmodes, 1)), &
                           zmodes(max(nmodes, 1))
    !> > 0: modes of their own for every harmonic h (cyclic sectors: nodal diameter h EO
    !> mod N), psi(:, :, h + 1) complex shapes on all DoFs, omega and zeta per harmonic
    integer(4), intent(in) :: hmodes
    complex(8), intent(in) :: psi(ndof, max(hmodes, 1), nh + 1)
    real(8), intent(in) :: wharm(max(hmodes, 1), nh + 1), zharm(max(hmodes, 1), nh + 1)
    integer(4), intent(in) :: ny
    real(8), intent(in) :: y0(ny), lam0, tan0(ny + 1)
    integer(4), intent(in) :: start_mode   !! one of HBM_START_*
    integer(4), intent(in) :: nropt, niopt
    real(8), intent(in) :: ropt(nropt)     !! (N_RCONT) real settings by RCONT_* slot
    integer(4), intent(in) :: iopt(niopt)  !! (N_ICONT) integer settings by ICONT_* slot
    integer(4), intent(in) :: stability    !! 1: Hill stability of every point
    integer(4), intent(in) :: history      !! 1: carry contact sliders from point to point
    integer(4), intent(in) :: maxpts, netot, ntim   !! ntim = N_TIMERS
    real(8), intent(out) :: ys(ny, maxpts), lams(maxpts), tans(ny + 1, maxpts)
    integer(4), intent(out) :: iters(maxpts)
    real(8), intent(out) :: xo(nout, 2*nh + 1, maxpts), states(3, netot, maxpts)
    real(8), intent(out) :: hill_re(maxpts)   !! max real part of the Floquet exponents, 1/s
    !> contact history each point leaves: the sliders its closed cycles start with, in the
    !> layout of w0 (the w0 to restart a run from that point)
    real(8), intent(out) :: sliders(nw0, maxpts)
    !> the arc-length scale of the unknowns each point's tangent is in (grown with the
    !> solution after every point): resume from a point with its tangent and this
    real(8), intent(out) :: yscales(maxpts)
    integer(4), intent(out) :: npts, finished
    real(8), intent(out) :: ds_out, timings(ntim)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    !> the LU carried from run to run of the same model (hbm_lu_holds; nlu = 0 or 1 and a
    !> dummy when it is not): dgetrf (lustate(1) = 1) or sgetrf (2) factors and pivots,
    !> lustate(1) = 0 when invalid, lustate(2) the GMRES iterations spent on it; read at
    !> the start, written at the end
    integer(4), intent(in) :: nlu
    real(8), intent(inout) :: lu(nlu, nlu), lustate(2)
    integer(4), intent(inout) :: lupiv(nlu)
    !> selected = 1: solve only for the (nonlinear DoF, harmonic) pairs with keep(j, h+1)
    !> = 1, the others zero (hbm_set_selection); y0, tan0, ys and tans keep the full
    !> layout (zeros where left out)
    integer(4), intent(in) :: selected, keep(nnl, nh + 1)
    !> selected = 2: also pair(j, h+1) = s k, the pairs of one travelling direction
    !> (hbm_set_selection's pair; 0: none); the points keep both members of a pair
    integer(4), intent(in) :: pair(nnl, nh + 1)
    real(8), intent(out) :: leak(maxpts)     !! per point: frirom_hbm cond_leak
    !> selected = 3: pairs, and Newton's evaluations run the AFT on one contact element per
    !> orbit (hbm_set_orbits, elements matched to orbtol); orbinfo = the elements the AFT
    !> runs on, the largest misfit accepted
    real(8), intent(in) :: orbtol
    real(8), intent(out) :: orbinfo(2)
    !> each element's orbit representative (hbm_set_orbits' map): 0 on the first call of
    !> a run, which writes it; later calls of the run pass it back
    integer(4), intent(inout) :: orbmap(netot)
    class(hbm_system), allocatable :: sys
    integer(ip), allocatable :: sel(:), omap(:)
    real(wp), allocatable :: ysel(:, :), tsel(:, :)
    type(cont_options) :: opts
    real(wp), allocatable :: y(:), t(:)
    real(wp) :: lam, dsl
    integer(ip) :: linfo, np, itl(maxpts), mode, n, k, nrep
    real(wp) :: mis
    integer(8) :: c0, c1, rate
    logical :: fin
    call system_clock(c0, rate)
    msg = ''
    info = 0
    npts = 0
    finished = 0
    ds_out = 0.0d0
    timings = 0.0d0
    ys = 0.0d0
    lams = 0.0d0
    tans = 0.0d0
    iters = 0
    xo = 0.0d0
    states = 0.0d0
    sliders = 0.0d0
    yscales = 0.0d0
    hill_re = 0.0d0
    leak = 0.0d0
    orbinfo = 0.0d0
    linfo = 0
    if (nropt /= N_RCONT .or. niopt /= N_ICONT .or. ntim /= N_TIMERS) then
        call set_status(linfo, FRIROM_ERR_SIZE, msg, 'hbm_continue: ropt, iopt and timings '// &
                        'need N_RCONT, N_ICONT and N_TIMERS entries')
    else if (lam_kind == 'frequency') then
        mode = HBM_FREQUENCY
    else if (lam_kind == 'load') then
        mode = HBM_LOAD
    else
        call set_status(linfo, FRIROM_ERR_PARAM, msg, "lam_kind must be 'frequency' or 'load'")
    end if
    if (linfo == 0) then
        if (formulation == 'condensed') then
            allocate (hbm_condensed :: sys)
        else if (formulation == 'banded') then
            allocate (hbm_full :: sys)
        else
            call set_status(linfo, FRIROM_ERR_PARAM, msg, "formulation must be 'condensed' "// &
                            "or 'banded'")
        end if
    end if
    if (linfo /= 0) then
        info = linfo
        return
    end if
    call hbm_setup(sys, nh, nsamp, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, mode, omega_fix, ginfo, gp, gi, gx, params, w0, outdofs, linfo, msg, &
                   contact_coords=tcontact == 1, krylov=int(krylov, ip), sparse_lu=sparse == 1)
    if (linfo == 0 .and. (sys%n /= ny .or. sum(ginfo(2, :)) /= netot)) &
        call set_status(linfo, FRIROM_ERR_SIZE, msg, 'hbm_continue: ny or netot does not '// &
                        'match the model')
    if (linfo == 0 .and. nmodes > 0) call hbm_set_modes(sys, phi, wmodes, zmodes, linfo, msg)
    if (linfo == 0 .and. hmodes > 0) call hbm_set_modes_harmonic(sys, psi, wharm, zharm, &
                                                                 linfo, msg)
    if (linfo == 0 .and. selected /= 0) then
        if (stability /= 0) then
            call set_status(linfo, FRIROM_ERR_PARAM, msg, 'selection: Hill stability would '// &
                            'see only perturbations inside the selection; not with stability')
        else
            if (selected >= 2) then
                call hbm_set_selection(sys, int(keep, ip), linfo, msg, sel, int(pair, ip))
                if (linfo == 0 .and. selected == 3) then
                    allocate (omap(netot))
                    omap = orbmap
                    call hbm_set_orbits(sys, orbtol, nrep, mis, linfo, msg, omap)
                    orbmap = int(omap, 4)
                    orbinfo = [real(nrep, 8), mis]
                end if
            else
                call hbm_set_selection(sys, int(keep, ip), linfo, msg, sel)
            end if
        end if
    end if
    if (linfo /= 0) then
        info = linfo
        return
    end if
    sys%carry = history /= 0
    call hbm_lu_import(sys, lu, lupiv, lustate)
    opts = cont_options_from(ropt, iopt)
    opts%max_points = maxpts
    y = y0
    t = tan0
    lam = lam0
    dsl = ropt(RCONT_DS)
    if (allocated(sel)) then
        ! the run in the kept unknowns; the points back in the full layout
        n = sys%n
        deallocate (y, t)
        allocate (y(n), t(n + 1), ysel(n, maxpts), tsel(n + 1, maxpts))
        call hbm_sel_reduce(sys, y0, y)
        call hbm_sel_reduce(sys, tan0(1:ny), t(1:n))
        t(n + 1) = tan0(ny + 1)
        call hbm_run(sys, start_mode, y, lam, t, dsl, ropt(RCONT_LAM_LO), opts, ysel, lams, &
                     tsel, itl, xo, states, np, fin, linfo, msg, sliders=sliders, &
                     yscales=yscales, leak=leak)
        do k = 1, np
            call hbm_sel_expand(sys, ysel(:, k), ys(:, k))
            call hbm_sel_expand(sys, tsel(1:n, k), tans(1:ny, k))
        end do
        tans(ny + 1, 1:np) = tsel(n + 1, 1:np)
    else if (stability /= 0) then
        call hbm_run(sys, start_mode, y, lam, t, dsl, ropt(RCONT_LAM_LO), opts, ys, lams, &
                     tans, itl, xo, states, np, fin, linfo, msg, hill_re, sliders=sliders, &
                     yscales=yscales)
    else
        call hbm_run(sys, start_mode, y, lam, t, dsl, ropt(RCONT_LAM_LO), opts, ys, lams, &
                     tans, itl, xo, states, np, fin, linfo, msg, sliders=sliders, &
                     yscales=yscales)
    end if
    call hbm_lu_export(sys, lu, lupiv, lustate)
    npts = np
    iters = itl
    finished = merge(1, 0, fin)
    ds_out = dsl
    info = linfo
    timings(1:N_TIMERS - 1) = sys%timers(1:N_TIMERS - 1)
    call system_clock(c1)
    timings(N_TIMERS) = real(c1 - c0, 8)/real(rate, 8)
end subroutine hbm_continue

!> Whether hbm_continue carries the LU from run to run (hold = 1, then pass nlu = n arrays)
!> for a condensed modal system in direct mode of nnl unknowns per harmonic coefficient,
!> nh harmonics and nmodes modes (frirom_hbm cond_lu_holds).
subroutine hbm_lu_holds(nh, nnl, nmodes, hold)
    use frirom_kinds, only: ip
    use frirom_hbm, only: cond_lu_holds
    implicit none
    integer(4), intent(in) :: nh, nnl, nmodes
    integer(4), intent(out) :: hold
    hold = merge(1, 0, cond_lu_holds(int(nh, ip), int(nnl, ip), int(nmodes, ip)))
end subroutine hbm_lu_holds

!> Value of a named integer constant of this interface, so that Python reads slots, modes
!> and codes from Fortran instead of typing their numbers: RCONT_*, N_RCONT, ICONT_*,
!> N_ICONT (option slots of hbm_continue, frirom_newton), HBM_START_* (start modes),
!> T_*, N_EVAL, N_FACT, N_KRYLOV, N_DOUBLE, N_TIMERS (timings slots, frirom_hbm) and the FRIROM_*
!> status codes.
!> An unknown name returns info = FRIROM_ERR_PARAM.
!> The default AFT samples per period for nh harmonics (frirom_solve's rule, the one place
!> it is written; frirom.harmonics.default_samples reads it).
subroutine default_samples(nh, ns)
    use frirom_kinds, only: ip
    use frirom_solve, only: frf_default_samples
    implicit none
    integer(4), intent(in) :: nh
    integer(4), intent(out) :: ns
    ns = int(frf_default_samples(int(nh, ip)), 4)
end subroutine default_samples

subroutine int_constant(name, value, info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_PARAM, frirom_status_code, set_status
    use frirom_newton, only: RCONT_TOL_R, RCONT_TOL_X, RCONT_TOL_STALL, RCONT_YSCALE, &
                             RCONT_LSCALE, RCONT_DS, RCONT_DS_MIN, RCONT_DS_MAX, RCONT_LAM_END, &
                             RCONT_LAM_LO, N_RCONT, ICONT_MAX_ITER, ICONT_REUSE_JAC, N_ICONT
    use frirom_hbm, only: T_AFT, T_ASM, T_FACT, T_SOLVE, T_REC, N_EVAL, N_FACT, N_KRYLOV, &
                          N_DOUBLE, N_TIMERS, HILL_DENSE_MAX, &
                          HBM_START_CONTINUE, HBM_START_RESUME, HBM_START_SOLVE_ONLY
    implicit none
    character(len=*), intent(in) :: name
    integer(4), intent(out) :: value
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    integer(ip) :: linfo
    msg = ''
    info = 0
    select case (name)
    case ('RCONT_TOL_R')
        value = RCONT_TOL_R
    case ('RCONT_TOL_X')
        value = RCONT_TOL_X
    case ('RCONT_TOL_STALL')
        value = RCONT_TOL_STALL
    case ('RCONT_YSCALE')
        value = RCONT_YSCALE
    case ('RCONT_LSCALE')
        value = RCONT_LSCALE
    case ('RCONT_DS')
        value = RCONT_DS
    case ('RCONT_DS_MIN')
        value = RCONT_DS_MIN
    case ('RCONT_DS_MAX')
        value = RCONT_DS_MAX
    case ('RCONT_LAM_END')
        value = RCONT_LAM_END
    case ('RCONT_LAM_LO')
        value = RCONT_LAM_LO
    case ('N_RCONT')
        value = N_RCONT
    case ('ICONT_MAX_ITER')
        value = ICONT_MAX_ITER
    case ('ICONT_REUSE_JAC')
        value = ICONT_REUSE_JAC
    case ('N_ICONT')
        value = N_ICONT
    case ('HBM_START_CONTINUE')
        value = HBM_START_CONTINUE
    case ('HBM_START_RESUME')
        value = HBM_START_RESUME
    case ('HBM_START_SOLVE_ONLY')
        value = HBM_START_SOLVE_ONLY
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
