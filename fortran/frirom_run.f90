!> A forced-response run that lives across calls: the one continuation driver of frirom.
!> Python (frirom_f2py), C (frirom_capi, frirom.h) and legacy Fortran (this module; and
!> frirom_solve's frf_solve, a convenience loop over it) drive the same calls:
!>
!>   run_open             the model from plain arrays, its formulation and the settings
!>   run_set_modes        receptances by modal superposition (real modes, or complex modes
!>   run_set_modes_harmonic   of their own per harmonic: a cyclic sector)
!>   run_set_selection    a travelling-wave selection, its direction (pairs) and orbits
!>   run_start            from nothing (the first point; a homotopy start in the excitation
!>                        level when Newton from the linear solution fails), from a point
!>                        (solved first), or from a checkpoint (exactly where it was made)
!>   run_advance          up to k more points of the curve, each with its checkpoint data
!>   run_solve            one corrector at a fixed parameter, or a step of given length
!>                        from a point along its tangent (peak refinement), on the same
!>                        system: nothing is set up again
!>   run_close
!>
!> The run owns the system (FFTW plans, receptance caches, MUMPS handles, the held
!> factorisation, the orbit map, the sliders) and the continuation state (point, tangent,
!> step, scales, the pending first point, the stop reason). It keeps a copy of the model's
!> arrays, from which the homotopy start builds a second run (the same model under a load
!> continuation). No module state: two runs in one process never share anything.
!>
!> Exact resume: every call of run_advance is one segment that starts from the last point
!> with its tangent, in the arc-length scale of that tangent, and with no factorisation
!> carried into it (as a restored run starts), so a run restored from the checkpoint of a
!> segment's last point (unknowns, parameter, tangent, yscale, ds_next, sliders, points
!> made) continues bit for bit as the uninterrupted run did.
module frirom_run
    use, intrinsic :: iso_c_binding, only: c_int, c_double, c_intptr_t, c_ptr, c_loc, &
                                           c_f_pointer
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, FRIROM_ERR_CONT, &
                             FRIROM_ERR_ALLOC, set_status
    use frirom_hbm, only: hbm_system, N_TIMERS
    use frirom_user_law, only: user_law
    implicit none
    private
    public :: run_t, run_model, run_settings, run_points
    public :: run_open, run_build, run_set_modes, run_set_modes_harmonic, run_set_selection, &
              run_start, run_advance, run_solve, run_close, run_get_sliders, run_set_sliders, &
              run_advice, run_sizes, run_default_samples, settings_pack, settings_unpack, &
              run_settings_names, run_handle, run_from_handle, run_checkpoint_size, &
              run_checkpoint, run_restore, run_contact_coords, open_run, run_lu_size, &
              run_lu_state, run_set_free_bodies, run_set_nonlinear_mode, run_to_mode, &
              run_set_user_law
    public :: RUN_CONDENSED, RUN_BANDED, RUN_FREQUENCY, RUN_LOAD, RUN_MODE, &
              RUN_START_COLD, RUN_START_POINT, RUN_START_RESUME, &
              RUN_GOING, RUN_DONE, RUN_MAX_POINTS, RUN_LEFT_RANGE, RUN_FAILED, RUN_STALLED, &
              STALL_POINTS, STALL_PROGRESS, &
              RUN_SOLVE_FIXED, RUN_SOLVE_STEP, &
              ADVISE_TOL_STALL, ADVISE_MAX_ITER, ADVISE_DS_MIN, ADVISE_SAMPLES, &
              N_ISET, N_RSET, COORD_AUTO, COORD_DOFS, COORD_CONTACT

    !> The formulations (unknowns): the contact DoFs' harmonics (Eq. 5-9) or all DoFs'
    !> harmonics (banded LU in RCM order).
    integer(ip), parameter :: RUN_CONDENSED = 1, RUN_BANDED = 2
    !> The parameter: the frequency (rad/s), or a load factor at a fixed frequency.
    integer(ip), parameter :: RUN_FREQUENCY = 1, RUN_LOAD = 2
    !> A nonlinear mode (EPMC, frirom_hbm_epmc): lam = log10 of the modal amplitude, the
    !> frequency and the artificial damping among the unknowns (run_set_nonlinear_mode).
    integer(ip), parameter :: RUN_MODE = 3
    !> How run_start begins: from nothing (Newton from the linear solution, then the
    !> homotopy start); from a point solved at its parameter first; from a point with
    !> its tangent (a checkpoint when its step is given).
    integer(ip), parameter :: RUN_START_COLD = 0, RUN_START_POINT = 1, RUN_START_RESUME = 2
    !> Why a run stopped (run_t%status): still going, reached the end of its range, made
    !> max_points points, turned back and left the range, a corrector failed.
    integer(ip), parameter :: RUN_GOING = 0, RUN_DONE = 1, RUN_MAX_POINTS = 2, &
                              RUN_LEFT_RANGE = 3, RUN_FAILED = 4, RUN_STALLED = 5
    !> A run stalls when its last STALL_POINTS points moved the parameter by less than
    !> STALL_PROGRESS of its range: more points or a resume would only repeat them.
    integer(ip), parameter :: STALL_POINTS = 200
    real(wp), parameter :: STALL_PROGRESS = 1.0e-6_wp
    !> run_solve: at a fixed parameter, or a step of given length from a point.
    integer(ip), parameter :: RUN_SOLVE_FIXED = 1, RUN_SOLVE_STEP = 2
    !> run_advice bits: settings that would change the outcome of a run stopped at ds_min
    !> with friction contacts (tol_stall above a stalled residual below the sampling error,
    !> max_iter where only the update test was missing, a smaller ds_min, the default
    !> samples for H).
    integer(ip), parameter :: ADVISE_TOL_STALL = 1, ADVISE_MAX_ITER = 2, ADVISE_DS_MIN = 4, &
                              ADVISE_SAMPLES = 8
    !> Condensed unknowns: chosen by run_contact_coords, the contact DoFs, or the contact
    !> coordinates G x.
    integer(ip), parameter :: COORD_AUTO = 0, COORD_DOFS = 1, COORD_CONTACT = 2
    !> Entries of settings_pack's integer and real arrays (the fields of run_settings in
    !> their order).
    integer(ip), parameter :: N_ISET = 9, N_RSET = 6

    !> Solver settings: the one place their defaults are written (frirom.h struct
    !> frirom_settings; Python's SolverOptions reads them through settings_pack). Steps are
    !> dimensionless (unknowns / |first point|, parameter / range).
    type, bind(c) :: run_settings
        integer(c_int) :: harmonics = 3        !! H: harmonics 0..H
        integer(c_int) :: samples = 0          !! AFT samples per period; 0: the default
        integer(c_int) :: formulation = RUN_CONDENSED
        integer(c_int) :: max_points = 2000    !! points of the curve at most
        integer(c_int) :: max_iter = 25        !! Newton iterations per corrector
        integer(c_int) :: batch = 10           !! points per segment (run_advance call)
        integer(c_int) :: reuse_jacobian = 1   !! 1: keep a factorisation while it contracts
        integer(c_int) :: history = 1          !! 1: carry the contact sliders along the curve
        integer(c_int) :: stability = 0        !! 1: Hill's method at every point
        real(c_double) :: tol_residual = 1.0e-8_c_double
        real(c_double) :: tol_update = 1.0e-8_c_double
        real(c_double) :: tol_stall = 0.0_c_double
        real(c_double) :: ds = 0.02_c_double   !! first arc-length step
        real(c_double) :: ds_min = 1.0e-6_c_double
        real(c_double) :: ds_max = 0.1_c_double
    end type run_settings

    !> The model as run_open took it (kept: a homotopy start builds a second run from it).
    type :: run_model
        integer(ip) :: formulation = RUN_CONDENSED, mode = RUN_FREQUENCY
        integer(ip) :: nh = 0, nsamp = 0, ndof = 0, krylov = 0
        real(wp) :: omega_fix = 0.0_wp
        logical :: tcontact = .false., sparse = .false.
        integer(ip), allocatable :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:), perm(:), nl(:)
        real(wp), allocatable :: kx(:), mx(:), cx(:)
        real(wp), allocatable :: fe0(:, :), fe1(:, :)     !! (ndof, 2H+1)
        integer(ip), allocatable :: ginfo(:, :), gp(:), gi(:), outdofs(:)
        real(wp), allocatable :: gx(:), params(:), w0(:)
        !> receptances by modes (run_set_modes / run_set_modes_harmonic), when allocated
        real(wp), allocatable :: phi(:, :), wm(:), zm(:)
        complex(wp), allocatable :: psi(:, :, :)
        real(wp), allocatable :: wh(:, :), zh(:, :)
        !> the selection (run_set_selection), when allocated
        integer(ip), allocatable :: keep(:, :), pair(:, :)
        logical :: orbits = .false.
        real(wp) :: orbtol = 1.0e-9_wp
        !> bodies held only by their contacts (run_set_free_bodies)
        logical :: free = .false.
        !> a mode run (RUN_MODE): the linear mode it starts from and its frequency (rad/s)
        real(wp), allocatable :: mode_phi(:)
        real(wp) :: mode_w0 = 0.0_wp
        !> a condensed mode run: the modes of its receptances (ndof, nm), rad/s, ratios
        real(wp), allocatable :: mode_modes(:, :), mode_wm(:), mode_zm(:)
        !> the callback of the user laws (run_set_user_law): kept with the model, so that
        !> a rebuilt system and a homotopy's child run evaluate them too
        type(user_law) :: ulaw
    end type run_model

    !> Points of a run (run_advance, run_solve), in the full layout of the unknowns.
    type :: run_points
        integer(ip) :: npts = 0
        real(wp), allocatable :: y(:, :)         !! (ny, npts) unknowns
        real(wp), allocatable :: lam(:)          !! (npts) parameter
        real(wp), allocatable :: tan(:, :)       !! (ny+1, npts) unit tangent (scaled)
        integer(ip), allocatable :: iters(:)     !! (npts) Newton iterations
        real(wp), allocatable :: xo(:, :, :)     !! (nout, 2H+1, npts) output harmonics
        real(wp), allocatable :: states(:, :, :) !! (3, n_elements, npts) stick/slip/open
        real(wp), allocatable :: hill(:)         !! (npts) max Re Floquet exponent, 1/s
        real(wp), allocatable :: sliders(:, :)   !! (max(nw, 1), npts) history it leaves
        real(wp), allocatable :: yscale(:)       !! (npts) scale of its tangent
        real(wp), allocatable :: leak(:)         !! (npts) selection's leak (0: none)
        !> (npts) the step the run continues with after the point, where the point is a
        !> checkpoint (the last of a segment); 0 elsewhere
        real(wp), allocatable :: ds_next(:)
        integer(ip), allocatable :: fold(:)      !! (npts) 1: the tangent turned in lam
    end type run_points

    !> A run: the model, the system built from it and the continuation state. Owned by
    !> the caller (Python, C: behind an opaque handle); run_close frees it.
    type :: run_t
        !> set by run_open, cleared by run_close: the C and f2py handles check it
        integer(ip) :: magic = 0
        type(run_model) :: m
        type(run_settings) :: s
        class(hbm_system), allocatable :: sys
        logical :: built = .false.
        integer(ip) :: ny = 0, nw = 0, netot = 0, nout = 0
        !> orbits found by run_set_selection: elements the AFT runs on, largest misfit
        integer(ip) :: orb_nrep = 0
        real(wp) :: orb_mis = 0.0_wp
        !> the range and arc-length scale of the parameter
        real(wp) :: lam_start = 0.0_wp, lam_end = 1.0_wp, lam_lo = 0.0_wp, lscale = 1.0_wp
        !> where the next segment starts, in the full layout: unknowns, tangent (ny+1)
        real(wp), allocatable :: y(:), t(:)
        real(wp) :: lam = 0.0_wp, ds = 0.0_wp, yscale = 1.0_wp
        integer(ip) :: start_mode = 0
        !> the first point awaits its tangent from the next segment
        logical :: pending = .false.
        type(run_points) :: first
        !> last tangent's parameter part (fold flags); points made before a resume and in
        !> this run (both count to max_points)
        real(wp) :: prev_t = 0.0_wp
        logical :: have_prev = .false.
        integer(ip) :: n_before = 0, n_made = 0
        integer(ip) :: status = RUN_GOING
        !> the last STALL_POINTS points' parameter, |unknowns| and |outputs| (a ring,
        !> filled up to n_ring), for the stall test and its diagnosis
        real(wp) :: ring(3, STALL_POINTS) = 0.0_wp
        integer(ip) :: n_ring = 0
        !> status code and message of the failure that stopped the run
        integer(ip) :: fail_info = FRIROM_OK
        character(len=512) :: message = ''
        !> timers and counters of the last call (frirom_hbm T_*, N_*; N_TIMERS: wall s)
        real(wp) :: timers(N_TIMERS) = 0.0_wp
        !> a run_solve between segments used the system: the LU the continuation held
        !> (hbm_lu_state, kept in lu_saved) is made again before the next segment
        logical :: lu_dirty = .false.
        real(wp), allocatable :: lu_saved(:)
    end type run_t

    integer(ip), parameter, public :: RUN_MAGIC = 1718185577

    interface
        !> Open a run on a model: check and keep the arrays, build the system. K, M, C and
        !> G in 1-based CSR; perm the RCM order of the DoFs; nl the nonlinear DoFs
        !> (condensed); fe0, fe1 (ndof, 2H+1) the excitation (frequency: fe0; load: fe0 +
        !> lam fe1 at omega_fix); ginfo (3, ngroup) law, elements, directions; params and
        !> w0 the groups' parameters and sliders concatenated; outdofs the output DoFs.
        module subroutine run_open(run, s, formulation, mode, nsamp, ndof, kp, ki, kx, mp, &
                                   mi, mx, cp, ci, cx, perm, nl, fe0, fe1, omega_fix, ginfo, &
                                   gp, gi, gx, params, w0, outdofs, tcontact, krylov, &
                                   sparse, info, errmsg)
            type(run_t), intent(inout) :: run
            type(run_settings), intent(in) :: s
            integer(ip), intent(in) :: formulation, mode, nsamp, ndof
            integer(ip), intent(in) :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:), perm(:), nl(:)
            real(wp), intent(in) :: kx(:), mx(:), cx(:)
            real(wp), intent(in) :: fe0(:, :), fe1(:, :)
            real(wp), intent(in) :: omega_fix
            integer(ip), intent(in) :: ginfo(:, :), gp(:), gi(:), outdofs(:)
            real(wp), intent(in) :: gx(:), params(:), w0(:)
            logical, intent(in) :: tcontact, sparse
            integer(ip), intent(in) :: krylov
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_open

        !> (Re)build the system from run%m (after run_open and each run_set_*).
        module subroutine run_build(run, info, errmsg)
            type(run_t), intent(inout) :: run
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_build

        !> Condensed receptances by superposition of real mass-normalised modes phi (ndof,
        !> nm), natural frequencies wm (rad/s) and damping ratios zm.
        module subroutine run_set_modes(run, phi, wm, zm, info, errmsg)
            type(run_t), intent(inout) :: run
            real(wp), intent(in) :: phi(:, :), wm(:), zm(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_set_modes

        !> Modes of their own for every harmonic h: psi (ndof, nm, H+1) complex shapes,
        !> wh, zh (nm, H+1) (a cyclic sector: harmonic h on nodal diameter h EO mod N).
        module subroutine run_set_modes_harmonic(run, psi, wh, zh, info, errmsg)
            type(run_t), intent(inout) :: run
            complex(wp), intent(in) :: psi(:, :, :)
            real(wp), intent(in) :: wh(:, :), zh(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_set_modes_harmonic

        !> A mode run (opened with mode RUN_MODE): the linear mode phi (ndof; stuck or
        !> free, the caller's choice) and its natural frequency omega0 (rad/s) the
        !> nonlinear mode starts from (frirom_run_modes.f90). Needed before run_start.
        !> A condensed run (formulation RUN_CONDENSED) needs the modes of its receptances:
        !> modes (ndof, nm), their frequencies wm (rad/s) and damping ratios zm.
        module subroutine run_set_nonlinear_mode(run, phi, omega0, info, errmsg, modes, wm, &
                                                 zm)
            type(run_t), intent(inout) :: run
            real(wp), intent(in) :: phi(:), omega0
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            real(wp), intent(in), optional :: modes(:, :), wm(:), zm(:)
        end subroutine run_set_nonlinear_mode

        !> Make an open run (a frequency or load run, e.g. frf_open's) a nonlinear-mode run
        !> on the same model: mode RUN_MODE, on all DoFs (condensed false) or condensed by
        !> modes (run_set_nonlinear_mode then gives them); receptance modes, a selection,
        !> Krylov, sparse LU and Hill's method are dropped. The run is built again.
        module subroutine run_to_mode(run, condensed, info, errmsg)
            type(run_t), intent(inout) :: run
            logical, intent(in) :: condensed
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_to_mode

        !> Bodies held only by their contacts (on): the contacts' stuck stiffness moved
        !> into the linear part and taken back off the contact forces, each contact's mean
        !> relative displacement held by a weak spring (frirom_hbm_free); rebuilds the
        !> system. The solution is unchanged where it is determined.
        module subroutine run_set_free_bodies(run, on, info, errmsg)
            type(run_t), intent(inout) :: run
            logical, intent(in) :: on
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_set_free_bodies

        !> The function (and its context, passed back untouched) that evaluates the
        !> contact groups whose law is a user law (frirom_user_law user_law_fn; a negative
        !> law code, frirom_aft law_user_code), in every formulation. The run keeps only
        !> the pointers: the caller keeps the function and its context alive until
        !> run_close.
        module subroutine run_set_user_law(run, ulaw, info, errmsg)
            type(run_t), intent(inout) :: run
            type(user_law), intent(in) :: ulaw
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_set_user_law

        !> A travelling-wave selection keep (nnl, H+1) of the condensed unknowns; with
        !> pair (nnl, H+1) its direction; with orbits, Newton's evaluations on one element
        !> per orbit (matched to orbtol).
        module subroutine run_set_selection(run, keep, info, errmsg, pair, orbits, orbtol)
            type(run_t), intent(inout) :: run
            integer(ip), intent(in) :: keep(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            integer(ip), intent(in), optional :: pair(:, :)
            logical, intent(in), optional :: orbits
            real(wp), intent(in), optional :: orbtol
        end subroutine run_set_selection

        !> Start a continuation from lam_start to lam_end (kind RUN_START_*): cold (the
        !> first point at lam_start from the linear solution, by the homotopy start if
        !> Newton fails there: frequency runs), from the point y0 at lam0 (solved first),
        !> or resumed from y0 at lam0 with its tangent tan0 in the scale yscale (and, for a
        !> checkpoint, ds > 0, the step of the run that wrote it, lscale_old > 0 its
        !> parameter range; n_before its points). sliders: the history to start from
        !> (else the run's); lu: the held LU's state at the checkpoint (hbm_lu_state,
        !> made again: the run then continues bit for bit; without it, a new LU there).
        !> The first point is made here (cold, point) and handed out by the next
        !> run_advance, with its tangent.
        module subroutine run_start(run, kind, lam_start, lam_end, info, errmsg, lam0, y0, &
                                    tan0, yscale, ds, lscale_old, n_before, sliders, lu)
            type(run_t), intent(inout) :: run
            integer(ip), intent(in) :: kind
            real(wp), intent(in) :: lam_start, lam_end
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            real(wp), intent(in), optional :: lam0, y0(:), tan0(:), yscale, ds, lscale_old
            integer(ip), intent(in), optional :: n_before
            real(wp), intent(in), optional :: sliders(:), lu(:)
        end subroutine run_start

        !> Up to k more points (fewer at the end of the range, at max_points or a failure:
        !> run%status says which, run%message why). The points (with the pending first
        !> point) go to pts; info is nonzero only for bad calls (a failed corrector stops
        !> the run with status RUN_FAILED and its code in run%fail_info).
        module subroutine run_advance(run, k, pts, info, errmsg)
            type(run_t), intent(inout) :: run
            integer(ip), intent(in) :: k
            type(run_points), intent(inout) :: pts
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine run_advance

        !> One corrector on the run's system, without touching its continuation state:
        !> RUN_SOLVE_FIXED, at lam0 from y0 (purely relative update test); RUN_SOLVE_STEP,
        !> on the hyperplane at distance ds along tan0 (scale yscale, the run's lscale)
        !> from the point (y0, lam0). sliders: the history to solve from (else the run's);
        !> the run's history is kept. stability: Hill's method at the point.
        module subroutine run_solve(run, kind, lam0, y0, pts, info, errmsg, tan0, yscale, &
                                    ds, sliders, stability, cold)
            type(run_t), intent(inout) :: run
            integer(ip), intent(in) :: kind
            real(wp), intent(in) :: lam0, y0(:)
            type(run_points), intent(inout) :: pts
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            real(wp), intent(in), optional :: tan0(:), yscale, ds, sliders(:)
            logical, intent(in), optional :: stability
            !> y0 is the linear solution's start: a failed Newton is retried from the
            !> homotopy start (frequency runs)
            logical, intent(in), optional :: cold
        end subroutine run_solve
    end interface

contains

    !> AFT samples per period by default for H harmonics (frirom.harmonics.default_samples
    !> reads it): 512, or 16 per harmonic coefficient (2H+1) rounded up to a power of two
    !> when more.
    pure function run_default_samples(nh) result(ns)
        integer(ip), intent(in) :: nh
        integer(ip) :: ns
        ns = 512
        do while (ns < 16*(2*nh + 1))
            ns = 2*ns
        end do
    end function run_default_samples

    !> The settings as integer and real arrays in the order of run_settings' fields.
    pure subroutine settings_pack(s, iv, rv)
        type(run_settings), intent(in) :: s
        integer(ip), intent(out) :: iv(N_ISET)
        real(wp), intent(out) :: rv(N_RSET)
        iv = [integer(ip) :: s%harmonics, s%samples, s%formulation, s%max_points, &
              s%max_iter, s%batch, s%reuse_jacobian, s%history, s%stability]
        rv = [real(wp) :: s%tol_residual, s%tol_update, s%tol_stall, s%ds, s%ds_min, &
              s%ds_max]
    end subroutine settings_pack

    !> The settings from settings_pack's arrays.
    pure function settings_unpack(iv, rv) result(s)
        integer(ip), intent(in) :: iv(N_ISET)
        real(wp), intent(in) :: rv(N_RSET)
        type(run_settings) :: s
        s%harmonics = int(iv(1), c_int)
        s%samples = int(iv(2), c_int)
        s%formulation = int(iv(3), c_int)
        s%max_points = int(iv(4), c_int)
        s%max_iter = int(iv(5), c_int)
        s%batch = int(iv(6), c_int)
        s%reuse_jacobian = int(iv(7), c_int)
        s%history = int(iv(8), c_int)
        s%stability = int(iv(9), c_int)
        s%tol_residual = rv(1)
        s%tol_update = rv(2)
        s%tol_stall = rv(3)
        s%ds = rv(4)
        s%ds_min = rv(5)
        s%ds_max = rv(6)
    end function settings_unpack

    !> Names of settings_pack's entries, integers then reals, blank-separated (the field
    !> names of run_settings and frirom.solver.SolverOptions).
    pure function run_settings_names() result(names)
        character(len=160) :: names
        names = 'harmonics samples formulation max_points max_iter batch reuse_jacobian '// &
                'history stability tol_residual tol_update tol_stall ds ds_min '// &
                'ds_max'
    end function run_settings_names

    !> Sizes of a built run: unknowns per point (full layout), sliders, contact elements,
    !> outputs.
    subroutine run_sizes(run, ny, nw, netot, nout)
        type(run_t), intent(in) :: run
        integer(ip), intent(out) :: ny, nw, netot, nout
        ny = run%ny
        nw = run%nw
        netot = run%netot
        nout = run%nout
    end subroutine run_sizes

    !> The contact history the run's system holds (nw sliders, the layout of w0).
    subroutine run_get_sliders(run, w)
        use frirom_hbm, only: hbm_sliders
        type(run_t), intent(in) :: run
        real(wp), intent(out) :: w(:)    !! (max(nw, 1))
        w = 0.0_wp
        if (run%built .and. run%nw > 0) call hbm_sliders(run%sys, w)
    end subroutine run_get_sliders

    !> Set the contact history (w: nw sliders in the layout of w0).
    subroutine run_set_sliders(run, w, info, errmsg)
        use frirom_hbm, only: hbm_set_sliders
        type(run_t), intent(inout) :: run
        real(wp), intent(in) :: w(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = FRIROM_OK
        if (.not. run%built) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_set_sliders: the run is not open')
            return
        end if
        if (run%nw == 0) return
        if (size(w) /= run%nw) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'sliders: one value per slider '// &
                            'of the contact elements expected')
            return
        end if
        if (.not. all(abs(w) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'sliders: contains NaN or Inf')
            return
        end if
        call hbm_set_sliders(run%sys, w)
    end subroutine run_set_sliders

    !> Settings that would change the outcome of a run stopped at ds_min (status
    !> RUN_FAILED, code FRIROM_ERR_CONT) with friction contacts: ADVISE_* bits, and the
    !> corrector's stalled |R|/rref read from the message (-1 when it gives none).
    !> The AFT samples the contacts N times per period; a contact state switching at one
    !> of them makes the equations piecewise smooth and Newton can stall below the
    !> sampling error (~1/N^2).
    subroutine run_advice(run, bits, stalled)
        type(run_t), intent(in) :: run
        integer(ip), intent(out) :: bits
        real(wp), intent(out) :: stalled
        integer(ip) :: at, ios, n, ndef
        bits = 0
        stalled = -1.0_wp
        if (run%status /= RUN_FAILED .or. run%fail_info /= FRIROM_ERR_CONT .or. &
            run%nw == 0) return
        at = index(run%message, '|R|/rref =')
        if (at > 0) then
            read (run%message(at + 10:), *, iostat=ios) stalled
            if (ios /= 0 .or. .not. (stalled >= 0.0_wp)) stalled = -1.0_wp
        end if
        ndef = run_default_samples(int(run%s%harmonics, ip))
        n = run%s%samples
        if (n <= 0) n = ndef
        if (stalled >= 0.0_wp .and. run%s%tol_stall < stalled .and. &
            stalled <= 1.0_wp/real(n, wp)**2) bits = ior(bits, ADVISE_TOL_STALL)
        if (stalled >= 0.0_wp .and. stalled <= run%s%tol_residual) &
            bits = ior(bits, ADVISE_MAX_ITER)
        if (run%s%ds_min > 1.0e-4_wp) bits = ior(bits, ADVISE_DS_MIN)
        if (n < ndef) bits = ior(bits, ADVISE_SAMPLES)
    end subroutine run_advice

    !> Whether the condensed unknowns are the contact coordinates G x (nrows per harmonic
    !> coefficient) rather than the contact DoFs (nnl): always for COORD_CONTACT, never for
    !> COORD_DOFS, and for COORD_AUTO when they are fewer, unless Hill's method (stability)
    !> or a travelling-wave selection (selected) needs the DoFs. The one place of the rule
    !> (frirom._pack and frirom_solve's frf_open call it).
    pure logical function run_contact_coords(coordinates, nrows, nnl, stability, selected) &
        result(yes)
        integer(ip), intent(in) :: coordinates, nrows, nnl
        logical, intent(in) :: stability, selected
        yes = coordinates == COORD_CONTACT .or. (coordinates == COORD_AUTO .and. &
                                                 nrows < nnl .and. .not. stability .and. &
                                                 .not. selected)
    end function run_contact_coords

    !> Length of the run's checkpoint (run_checkpoint): 7 + 2 ny + 1 + nw + the held
    !> LU's state (run_lu_size).
    function run_checkpoint_size(run) result(n)
        type(run_t), intent(in) :: run
        integer(ip) :: n
        n = 8 + 2*run%ny + run%nw + run_lu_size(run)
    end function run_checkpoint_size

    !> Length of the held LU's state (frirom_hbm hbm_lu_state) of a built run, else 0.
    function run_lu_size(run) result(n)
        use frirom_hbm, only: hbm_lu_state_size
        type(run_t), intent(in) :: run
        integer(ip) :: n
        n = 0
        if (run%built) n = hbm_lu_state_size(run%sys)
    end function run_lu_size

    !> The state of the LU the run's continuation holds (hbm_lu_state; after a
    !> run_solve, the one kept for the next segment).
    subroutine run_lu_state(run, v)
        use frirom_hbm, only: hbm_lu_state
        type(run_t), intent(in) :: run
        real(wp), intent(out) :: v(:)     !! (run_lu_size)
        if (run%lu_dirty .and. allocated(run%lu_saved)) then
            v = run%lu_saved
        else
            call hbm_lu_state(run%sys, v)
        end if
    end subroutine run_lu_state

    !> Everything exact resume needs, after a run_advance (the end of a segment): the
    !> range, the point the next segment starts from (parameter, arc-length scale, step,
    !> points made, unknowns, tangent) and the contact history, as ck = [lam_start,
    !> lam_end, lam, yscale, ds, n_points, status, y (ny), t (ny+1), sliders (nw), the
    !> held LU's state (run_lu_size)].
    !> run_restore on a run opened on the same model continues bit for bit as this one.
    subroutine run_checkpoint(run, ck, info, errmsg)
        type(run_t), intent(in) :: run
        real(wp), intent(out) :: ck(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: ny
        info = FRIROM_OK
        ck = 0.0_wp
        if (run%magic /= RUN_MAGIC .or. .not. allocated(run%y)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_checkpoint: the run is '// &
                            'not started')
            return
        end if
        if (run%pending .or. run%n_made + run%n_before == 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_checkpoint: no segment '// &
                            'made yet (run_advance first)')
            return
        end if
        if (size(ck) /= run_checkpoint_size(run)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'run_checkpoint: ck needs '// &
                            'run_checkpoint_size entries')
            return
        end if
        ny = run%ny
        ck(1:7) = [run%lam_start, run%lam_end, run%lam, run%yscale, run%ds, &
                   real(run%n_before + run%n_made, wp), real(run%status, wp)]
        ck(8:7 + ny) = run%y
        ck(8 + ny:8 + 2*ny) = run%t
        if (run%nw > 0) call run_get_sliders(run, ck(9 + 2*ny:8 + 2*ny + run%nw))
        call run_lu_state(run, ck(9 + 2*ny + run%nw:))
    end subroutine run_checkpoint

    !> Continue from a checkpoint of a run on the same model (run_checkpoint): the run
    !> is started there and its next run_advance makes the points the checkpointed run
    !> made after it.
    subroutine run_restore(run, ck, info, errmsg)
        type(run_t), intent(inout) :: run
        real(wp), intent(in) :: ck(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: ny, st
        info = FRIROM_OK
        if (run%magic /= RUN_MAGIC) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_restore: the run is not open')
            return
        end if
        if (size(ck) /= run_checkpoint_size(run)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'run_restore: ck has not the '// &
                            'length of this run''s checkpoints (another model?)')
            return
        end if
        if (.not. all(abs(ck) <= huge(1.0_wp)) .or. ck(6) < 0.0_wp .or. ck(4) <= 0.0_wp .or. &
            ck(5) <= 0.0_wp .or. ck(7) < RUN_GOING .or. ck(7) > RUN_FAILED) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_restore: ck is no '// &
                            'checkpoint (NaN, a negative count or scale, or an unknown status)')
            return
        end if
        ny = run%ny
        if (run%nw > 0) then
            call run_set_sliders(run, ck(9 + 2*ny:8 + 2*ny + run%nw), info, errmsg)
            if (info /= 0) return
        end if
        call run_start(run, RUN_START_RESUME, ck(1), ck(2), info, errmsg, lam0=ck(3), &
                       y0=ck(8:7 + ny), tan0=ck(8 + ny:8 + 2*ny), yscale=ck(4), ds=ck(5), &
                       n_before=nint(ck(6), ip), lu=ck(9 + 2*ny + run%nw:))
        st = nint(ck(7), ip)
        if (info == 0 .and. st /= RUN_GOING) run%status = st
    end subroutine run_restore

    !> The opaque handle of an allocated run (its address), for callers across a language
    !> boundary (f2py, C); run_from_handle gives the run back.
    function run_handle(run) result(h)
        type(run_t), pointer, intent(in) :: run
        integer(c_intptr_t) :: h
        h = transfer(c_loc(run), h)
    end function run_handle

    !> The run behind a handle of run_handle; a null handle, or one of a closed run,
    !> gives FRIROM_ERR_PARAM naming `who` and run null.
    subroutine run_from_handle(h, run, who, info, errmsg)
        integer(c_intptr_t), intent(in) :: h
        type(run_t), pointer, intent(out) :: run
        character(len=*), intent(in) :: who
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(c_ptr) :: p
        info = FRIROM_OK
        nullify (run)
        if (h /= 0) then
            p = transfer(h, p)
            call c_f_pointer(p, run)
            if (run%magic /= RUN_MAGIC) nullify (run)
        end if
        if (.not. associated(run)) call set_status(info, FRIROM_ERR_PARAM, errmsg, who// &
                                                   ': handle is not an open run (closed, '// &
                                                   'or never opened)')
    end subroutine run_from_handle

    !> Whether the run is open and built; else info = FRIROM_ERR_PARAM naming the call.
    !> (Public: gfortran leaves out a private module procedure that only submodules call.)
    logical function open_run(run, who, info, errmsg)
        type(run_t), intent(in) :: run
        character(len=*), intent(in) :: who
        integer(ip), intent(inout) :: info
        character(len=*), intent(inout) :: errmsg
        open_run = run%built .and. run%magic == RUN_MAGIC
        if (.not. open_run) call set_status(info, FRIROM_ERR_PARAM, errmsg, who// &
                                            ': the run is not open (run_open first)')
    end function open_run

    !> Free everything the run holds; the run can be opened again.
    subroutine run_close(run)
        use frirom_aft, only: aft_plan_destroy
        type(run_t), intent(inout) :: run
        if (allocated(run%sys)) call aft_plan_destroy(run%sys%plan)
        run = run_t()
    end subroutine run_close
end module frirom_run
