!> Alternating frequency/time (AFT): harmonic coefficients of the relative displacements of
!> many contact elements -> harmonic coefficients of their forces, and the analytical
!> Jacobian d(force harmonics)/d(displacement harmonics), one block per element.
!>
!> Method, per batch of elements: displacements to time samples by batched inverse real
!> FFTs (up to H = DIRECT_MAX_HARM by one matrix product with the basis table instead:
!> frirom_fourier synth_direct); the law is marched (frirom_contact) period after period
!> until the slider returns to where it started (the cycle closes); forces back to
!> harmonics by batched real FFTs (or the table's product, analyse_direct).
!> The Jacobian never touches O(N H^2) work: a force that depends on the same-sample
!> displacement with a coefficient c_k contributes the matrix of multiplication by c,
!> built from the 4H+1 trigonometric sums of c; c is constant over runs of samples
!> (kt in stick, +-mu kn in slip, kn in contact), so the sums come from a prefix table
!> in O(H) per run. Dependence on an earlier sample (the slider, fixed at the last slip
!> sample or at the re-contact point after the last lift-off sample, the "anchor") adds
!> a rank-one term per stick segment (rank two after a re-contact, which moves with u and
!> v at the two samples around it). The 2-D law, whose slip direction remembers the past,
!> propagates the slider tangent instead.
!>
!> The 2-D slider corrects only its component along each slip direction, so plain
!> marching can contract its mismatch as little as 0.99 a period (the onset of partial
!> slip); its march takes Newton steps on the slider fixed point between periods, with
!> the 2x2 derivative of the period map from the slip tangents (frirom_aft_march), and
!> the Jacobian then solves the closed cycle's slider tangent directly. Where one period
!> determines the slider along a direction only weakly (det(I - M) < DET_ISOLATED: stuck,
!> or barely slipping to and fro along one line) the slider is history, as a stuck 1-D
!> slider is: marched plainly from w0 until it drifts by less than DRIFT a period, and
!> differentiated as marched.
!>
!> Cost per element: O(N) marching per period (usually 2 periods from a cold slider, about
!> 5 for the 2-D law near the onset of partial slip),
!> one inverse and one forward real FFT of length N per direction (O(N (2H+1)) by the
!> table at small H), and for the Jacobian an O(N) scan plus O(H^2) per run and per
!> stick segment. The 1-D laws allocate nothing per element: their work arrays live in
!> the plan.
!>
!> Choice of N: N >= 2H+1 is required. Friction forces are continuous with kinks, and
!> the march locates lift-off and re-contact between samples (frirom_contact), so the
!> force harmonics of the 1-D laws converge like O(N^-2) in every regime; the default N
!> is chosen from measurements in the Python package (frirom.harmonics.default_samples).
!> Use N >= 4H+1 for the cubic law to be exact. The 2-D law moves its slider exactly along
!> the interpolated path between samples (frirom_contact slip2d_step), so it converges
!> like O(N^-2) too, curved slip paths and lift-off included.
!>
!> Layout: this parent module holds the law table, the plan and the interfaces; the work
!> is in submodules by job: frirom_aft_eval (the two entry points and the checks of their
!> arguments), frirom_aft_march (time samples and the march until the cycle closes) and
!> frirom_aft_jacobian (the analytical Jacobian).
module frirom_aft
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_LAW, set_status
    use frirom_fourier, only: fourier_plan, fourier_plan_create, fourier_plan_destroy
    implicit none
    private

    public :: aft_plan, aft_plan_create, aft_plan_destroy, aft_eval, aft_time
    public :: LAW_JENKINS, LAW_NORMAL1D, LAW_NORMAL2D, LAW_CUBIC, LAW_IWAN4, LAW_IWAN, LAW_CODES
    public :: IWAN4_BINS, IWAN_MAX
    public :: law_info, law_check, law_ndir, law_npar, law_nslider, law_rest_force, &
              law_stuck_stiffness, law_user_code
    public :: iwan_sliders

    ! The contact-law table: the one source of the codes and sizes (the Python package
    ! checks its own table, with the names of directions and parameters, against it).
    integer(ip), parameter :: LAW_JENKINS = 1   !! u; kt, mu, fn0
    integer(ip), parameter :: LAW_NORMAL1D = 2  !! u, v; kt, kn, mu, n0
    integer(ip), parameter :: LAW_NORMAL2D = 3  !! u1, u2, v; kt, kn, mu, n0
    integer(ip), parameter :: LAW_CUBIC = 4     !! u; k1, k3
    integer(ip), parameter :: LAW_IWAN4 = 5     !! u; fs, kt, chi, beta (Segalman 2005)
    integer(ip), parameter :: LAW_IWAN = 6      !! u; k1, fs1, ..., k10, fs10 (parallel Jenkins)
    !> The four-parameter Iwan's density, discretised (frirom_aft_iwan): IWAN4_BINS Jenkins
    !> sliders for its power-law part plus one for its Dirac part at phi_max.
    integer(ip), parameter :: IWAN4_BINS = 30
    integer(ip), parameter :: IWAN_MAX = 10     !! sliders of the discrete Iwan
    integer(ip), parameter :: NLAW = 6
    !> Every law code, in the order of the tables below (code k at position k).
    integer(ip), parameter :: LAW_CODES(NLAW) = [LAW_JENKINS, LAW_NORMAL1D, LAW_NORMAL2D, &
                                                 LAW_CUBIC, LAW_IWAN4, LAW_IWAN]
    character(len=*), parameter :: LAW_NAMES(NLAW) = [character(len=8) :: 'jenkins', &
                                                      'normal1d', 'normal2d', 'cubic', &
                                                      'iwan4', 'iwan']
    integer(ip), parameter :: NDIR_OF(NLAW) = [1, 2, 3, 1, 1, 1]  !! relative displacements
    integer(ip), parameter :: NPAR_OF(NLAW) = [3, 4, 4, 2, 4, 2*IWAN_MAX]  !! parameters
    integer(ip), parameter :: NSLIDER_OF(NLAW) = [1, 1, 2, 0, IWAN4_BINS + 1, IWAN_MAX]

    integer(ip), parameter :: DEFAULT_BATCH = 16
    real(wp), parameter :: DEFAULT_TOL = 1.0e-12_wp
    integer(ip), parameter :: DEFAULT_MAX_PERIODS = 200
    !> A closed 2-D cycle is an isolated fixed point of the period map when
    !> det(I - dw_end/dw_start) >= this (stuck all cycle: 0; touching the friction limit
    !> with a slip of the order of the closure tolerance: ~1e-12; onset of partial slip at
    !> 0.991 a period: ~1e-2). Below it the slider is determined along one direction by
    !> less than this a period (a hook element of the paper mesh that barely slips to and
    !> fro along one line: 2.3e-6): like a stuck slider, it is history, carried from w0.
    !> (The fixed point's tangent is amplified by up to 1/det: with 1e-4 here the paper
    !> hooks' ROM_II at f0 = 300 N turned back at 131.2 Hz, with 1e-2 it runs through.)
    real(wp), parameter :: DET_ISOLATED = 1.0e-2_wp
    !> A cycle that is not isolated closes once its slider moves less than DRIFT times the
    !> displacement scale a period (its weak direction drifts by that, the force by kt
    !> times it: a relative error of DRIFT), where an exact closure to tol would take
    !> ~1/det periods. Where the number of periods marched changes between two Newton
    !> iterations the forces jump by up to that: 1e-7 and 1e-8 stalled paper-hooks sweeps
    !> at |R|/rref ~1e-8 (ROM_II 1 000 N down, 300 N up), 1e-9 runs them through.
    real(wp), parameter :: DRIFT = 1.0e-9_wp
    ! HELD (aft_forces' held): how many periods a history cycle takes to close changes with
    ! the motion, and the forces jump by up to DRIFT where it does: a Newton corrector whose
    ! iterations straddle such a change stalls at |R|/rref ~1e-8 (the coarse paper hooks'
    ! ROM_I at 180.2 Hz). A caller that holds the counts the first evaluation of a corrector
    ! finds (frirom_hbm: hbm_begin_correct clears them) marches those cycles exactly that
    ! many periods from w0 in every later evaluation: R is then one smooth function of the
    ! motion during the corrector, and the Jacobian (settle2d) is exactly its derivative.
    ! Where the corrector converges far from where the counts were found, a held cycle may
    ! not close there (a count of 1 found stuck, then slipping: its forces the first
    ! period's from w0, a transient): settled says so, and the corrector finds the counts
    ! afresh at its point and goes on (frirom_newton newton_correct).
    !> A held history cycle whose last period drifts by more than this times its scale
    !> does not close (settled): a transient, not the drift closure's rounding (held at
    !> DRIFT, a few 1e-9 after the corrector moved re-armed most BRB backbone points:
    !> 64 points and 50 s of CPU where 34 and 35 s do without; the free-body transient
    !> it is there for drifts by ~1e-2)
    real(wp), parameter :: UNSETTLED = 1.0e-6_wp

    !> Everything one caller needs to evaluate contact forces at H harmonics and N samples:
    !> FFTW plans, buffers and per-batch work arrays. Owned by the caller (one per thread).
    type :: aft_plan
        type(fourier_plan) :: fp
        integer(ip), allocatable :: state(:, :)      !! (nbatch, N) contact state per sample
        real(wp), allocatable :: tangent(:, :, :)    !! (nbatch, 12, N) 2-D slip tangents
        real(wp), allocatable :: follow(:, :, :)     !! (nbatch, N, 2) u the sliders follow
                                                     !! (frirom_contact recontact_follow)
        real(wp), allocatable :: par(:, :)           !! (nbatch, 4) parameters of the batch
        real(wp), allocatable :: w(:, :), wstart(:, :)  !! (nbatch, 2) slider positions
        real(wp), allocatable :: scale(:)            !! (nbatch) closure scale
        integer(ip), allocatable :: closed_at(:)     !! (nbatch) period the cycle closed in
        integer(ip), allocatable :: events(:)        !! (N+1) run starts of one element
        integer(ip), allocatable :: anchor(:)        !! (nbatch) last slip/lift-off sample
        integer(ip), allocatable :: anchor_state(:)  !! (nbatch) its state
        real(wp), allocatable :: anchor_dtv(:)       !! (nbatch) its d ft / dv
        real(wp), allocatable :: dw(:, :), dw0(:, :) !! (2, 3(2H+1)) 2-D slider tangent
        real(wp), allocatable :: dft(:, :)           !! (2, 3(2H+1)) 2-D force tangent
        real(wp), allocatable :: jw(:, :)            !! (2H+1, 3) 1-D Jacobian rows g, ru, rv
        real(wp), allocatable :: jt(:, :)            !! (0:2H, 6) 1-D Jacobian trig sums
        ! 2-D slider fixed point: Newton steps between periods (frirom_aft_march)
        real(wp), allocatable :: wplain(:, :)        !! (nbatch, 2) plain march from the base
        real(wp), allocatable :: res_base(:)         !! (nbatch) mismatch of the base period
        real(wp), allocatable :: res_last(:)         !! (nbatch) mismatch of the last period
        logical, allocatable :: stepped(:)           !! (nbatch) period started from a step
        logical, allocatable :: accelerated(:)       !! (nbatch) a step was accepted
        integer(ip), allocatable :: hold(:)          !! (nbatch) plain periods before a step
        real(wp), allocatable :: damp(:)             !! (nbatch) fraction of the step taken
        real(wp), allocatable :: damp_cap(:)         !! (nbatch) largest fraction since a
                                                     !! rejected step
        integer(ip), allocatable :: held(:)          !! (nbatch) aft_forces' held, 0: none
        !> (nbatch) a history cycle still drifting after max_periods periods (its slider is
        !> not handed on: aft_forces' slider is w0 for it)
        logical, allocatable :: drifting(:)
        logical, allocatable :: unsettled(:)         !! (nbatch) a held cycle not closed
    end type aft_plan

    ! The two entry points are generic names over separate module procedures: gfortran 12
    ! warns of an argument mismatch between a separate module procedure and an external
    ! procedure of the same name (the f2py wrappers aft_eval and aft_time).
    interface aft_eval
        !> Contact forces and (optionally) their Jacobian in harmonic form.
        !>
        !> x(2H+1, ndir, ne): harmonic coefficients of the local relative displacements of
        !> ne elements of one law; f: the forces in the same layout; jac(i, j, e) = d f_i /
        !> d x_j with flat index c + (2H+1)(d-1). w0(nslider, ne): slider position at the
        !> start of the march (0: spring unstretched at zero relative displacement, the
        !> configuration the FE model was built in, so an element stuck all cycle is exactly
        !> a linear spring). The march repeats until the slider closes its cycle to tol
        !> (relative to the displacement amplitude) or max_periods is reached
        !> (FRIROM_ERR_NOCLOSE, with the forces of the last period). periods(e): periods
        !> marched; states(:, e): fraction of samples in stick, slip and lift-off;
        !> slider(:, e): slider position with which the closed cycle starts (= where it
        !> ends, after the last sample); w0 for a history cycle still drifting after
        !> max_periods periods (handed on, it would advance by max_periods periods at
        !> every continuation point: a paper-hooks ROM_II sweep ratcheted in place at
        !> 134.76 Hz). A continuation passes slider back as the next point's w0, so that a
        !> contact entering stick-all-cycle keeps the slider where it last slipped (the
        !> stuck state is not unique; history decides it) instead of jumping back to w0. relative: f less the force at rest (law_rest_force: the
        !> normal preload on harmonic 0), its samples computed as kn v (-n0 open), not as
        !> (n0 + kn v) - n0: no rounding of the size eps n0 (a large preload).
        recursive module subroutine aft_forces(plan, law, x, params, w0, f, info, errmsg, jac, periods, &
                                     states, tol, max_periods, index_base, slider, relative, &
                                     held, settled)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law                !! LAW_*
            real(wp), intent(in) :: x(:, :, :)            !! (2H+1, ndir, ne), m
            real(wp), intent(in) :: params(:, :)          !! (npar, ne)
            real(wp), intent(in) :: w0(:, :)              !! (nslider, ne), m
            real(wp), intent(out) :: f(:, :, :)           !! (2H+1, ndir, ne), N
            integer(ip), intent(out) :: info
            character(len=*), intent(inout), optional :: errmsg
            real(wp), intent(out), optional :: jac(:, :, :)   !! (ndir(2H+1), ndir(2H+1), ne)
            integer(ip), intent(out), optional :: periods(:)  !! (ne)
            real(wp), intent(out), optional :: states(:, :)   !! (3, ne)
            real(wp), intent(in), optional :: tol             !! closure tolerance (1e-12)
            integer(ip), intent(in), optional :: max_periods  !! (200)
            integer(ip), intent(in), optional :: index_base   !! element numbering in messages
            real(wp), intent(out), optional :: slider(:, :)   !! (nslider, ne), m
            logical, intent(in), optional :: relative         !! (.false.)
            !> (ne) 2-D law: periods a history cycle is marched, held through a Newton
            !> corrector (see HELD below); 0 on entry: march and closure test as usual, and
            !> a history cycle's period count is returned to be held
            integer(ip), intent(inout), optional :: held(:)
            !> every cycle held in held (below max_periods) closes at this x: its last
            !> period drifts by at most UNSETTLED of the element's scale
            logical, intent(out), optional :: settled
        end subroutine aft_forces
    end interface aft_eval

    interface aft_time
        !> Time histories of the closed cycle: relative displacements xt and forces ft at
        !> the N samples, for hysteresis loops and contact-state plots.
        recursive module subroutine aft_histories(plan, law, x, params, w0, xt, ft, info, errmsg, tol, &
                                        max_periods, index_base)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law
            real(wp), intent(in) :: x(:, :, :)     !! (2H+1, ndir, ne)
            real(wp), intent(in) :: params(:, :)   !! (npar, ne)
            real(wp), intent(in) :: w0(:, :)       !! (nslider, ne)
            real(wp), intent(out) :: xt(:, :, :)   !! (N, ndir, ne)
            real(wp), intent(out) :: ft(:, :, :)   !! (N, ndir, ne)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout), optional :: errmsg
            real(wp), intent(in), optional :: tol
            integer(ip), intent(in), optional :: max_periods
            integer(ip), intent(in), optional :: index_base
        end subroutine aft_histories
    end interface aft_time

    ! The Iwan laws (frirom_aft_iwan): each element is a set of parallel Jenkins sliders
    ! marched, transformed and differentiated by the Jenkins AFT; forces and Jacobians sum.
    interface
        !> aft_forces for LAW_IWAN4 / LAW_IWAN (arguments checked by aft_forces).
        recursive module subroutine iwan_forces(plan, law, x, params, w0, f, info, errmsg, &
                                                jac, periods, states, tol, max_periods, &
                                                index_base, slider)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law
            real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :)
            real(wp), intent(out) :: f(:, :, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout), optional :: errmsg
            real(wp), intent(out), optional :: jac(:, :, :)
            integer(ip), intent(out), optional :: periods(:)
            real(wp), intent(out), optional :: states(:, :)
            real(wp), intent(in) :: tol
            integer(ip), intent(in) :: max_periods, index_base
            real(wp), intent(out), optional :: slider(:, :)
        end subroutine iwan_forces

        !> aft_histories for LAW_IWAN4 / LAW_IWAN.
        recursive module subroutine iwan_histories(plan, law, x, params, w0, xt, ft, info, &
                                                   errmsg, tol, max_periods, index_base)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law
            real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :)
            real(wp), intent(out) :: xt(:, :, :), ft(:, :, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout), optional :: errmsg
            real(wp), intent(in) :: tol
            integer(ip), intent(in) :: max_periods, index_base
        end subroutine iwan_histories

        !> The Jenkins sliders of one Iwan element: stiffness k(s) and slip force fs(s),
        !> s = 1..NSLIDER_OF(law); k(s) = 0 marks an unused slider.
        pure module subroutine iwan_sliders(law, p, k, fs)
            integer(ip), intent(in) :: law
            real(wp), intent(in) :: p(:)
            real(wp), intent(out) :: k(:), fs(:)
        end subroutine iwan_sliders
    end interface

    ! Private procedures that one submodule calls in another. (A private procedure of the
    ! parent that only submodules call must be declared here too: gfortran drops private
    ! module procedures its own unit does not use.)
    interface
        !> Elements e0..e0+m-1: displacement harmonics to time samples (input slots), then
        !> the law marched until their cycles close (frirom_aft_march).
        module subroutine time_batch(plan, law, x, params, w0, e0, m, tol, max_periods)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law, e0, m, max_periods
            real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :), tol
        end subroutine time_batch

        !> The slider fixed point w = P(w) of 2-D element j of the batch, P one period as
        !> just marched and M = dP/dw (frirom_aft_march slider_map): a = I - M, det its
        !> determinant, isolated = det >= DET_ISOLATED (the closed cycle's slider is then
        !> unique and its tangent solves a dw = r), opened: the period has a lift-off
        !> sample (M = 0). The march's Newton steps and isolation test and the Jacobian's
        !> solve all read this one routine.
        pure module subroutine slider_fixed_point(plan, j, a, det, isolated, opened)
            type(aft_plan), intent(in) :: plan
            integer(ip), intent(in) :: j
            real(wp), intent(out) :: a(2, 2), det
            logical, intent(out) :: isolated, opened
        end subroutine slider_fixed_point

        !> (x1, x2) = a^-1 (g1, g2) for slider_fixed_point's a (2 x 2, determinant det) by
        !> Cramer's rule, elementwise in g and x.
        pure elemental module subroutine cramer2(a11, a12, a21, a22, det, g1, g2, x1, x2)
            real(wp), intent(in) :: a11, a12, a21, a22, det, g1, g2
            real(wp), intent(out) :: x1, x2
        end subroutine cramer2

        !> Same-sample coefficient series of the 2-D law's Jacobian, written after the
        !> forces of the first m elements: slot 4 = kt [stick], slot 5 = kn [contact]. (The
        !> 1-D laws' Jacobian scans the states; the cubic's reads its spring's df/du.)
        pure module subroutine fill_series(plan, m)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: m
        end subroutine fill_series

        !> Jacobian block of element j of the batch, after fill_series and the forward
        !> transforms (frirom_aft_jacobian).
        module subroutine element_jacobian(plan, law, j, p, w0j, jac)
            type(aft_plan), intent(inout) :: plan
            integer(ip), intent(in) :: law, j
            real(wp), intent(in) :: p(:)        !! (npar) the element's parameters
            real(wp), intent(in) :: w0j(:)      !! (nslider) its initial slider, m
            real(wp), intent(inout) :: jac(:, :)  !! (ndir(2H+1), ndir(2H+1))
        end subroutine element_jacobian
    end interface

contains

    !> The law table for one code: number of directions, parameters and slider components,
    !> and the name; zeros and an empty name for an unknown code.
    pure subroutine law_info(law, ndir, npar, nslider, name)
        integer(ip), intent(in) :: law                    !! LAW_*
        integer(ip), intent(out) :: ndir                  !! relative displacement directions
        integer(ip), intent(out) :: npar                  !! parameters per element
        integer(ip), intent(out) :: nslider               !! slider components
        character(len=*), intent(out), optional :: name  !! e.g. 'jenkins'
        ndir = 0
        npar = 0
        nslider = 0
        if (known(law)) then            ! the table only (a user law's code: zeros)
            ndir = law_ndir(law)
            npar = law_npar(law)
            nslider = law_nslider(law)
        end if
        if (present(name)) then
            name = ''
            if (known(law)) name = LAW_NAMES(law)
        end if
    end subroutine law_info

    !> FRIROM_OK for a law code of the table, else FRIROM_ERR_LAW with a message listing
    !> the laws: 'law 9 (expected 1 jenkins, 2 normal1d, ...)'.
    !> user: also accept a user law's code (law_user_code; the solver evaluates those
    !> through the run's callback, frirom_user_law).
    pure subroutine law_check(law, info, errmsg, user)
        integer(ip), intent(in) :: law                     !! the code to check
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        logical, intent(in), optional :: user
        character(len=200) :: buf
        info = FRIROM_OK
        if (any(LAW_CODES == law)) return
        if (present(user)) then
            if (user .and. law < 0 .and. law_ndir(law) >= 1) return
        end if
        write (buf, '(a,i0,a,a,a)') 'law ', law, ' (expected ', law_list(), ')'
        call set_status(info, FRIROM_ERR_LAW, errmsg, trim(buf))
    end subroutine law_check

    !> The codes and names of all laws for messages: '1 jenkins, 2 normal1d, ...'.
    pure function law_list() result(text)
        character(len=:), allocatable :: text
        character(len=12) :: code
        integer(ip) :: k
        text = ''
        do k = 1, NLAW
            write (code, '(i0)') LAW_CODES(k)
            if (k > 1) text = text//', '
            text = text//trim(code)//' '//trim(LAW_NAMES(k))
        end do
    end function law_list

    !> The element's stiffness when closed and stuck, per direction (N/m): kt along the
    !> tangents, kn along the normal, k1 of a cubic spring. The linear part a body held
    !> only by its contacts borrows (hbm_setup's free bodies: G^T Ks G moved from the
    !> contact forces into K and subtracted back in contact_eval); any positive value
    !> would do in exact arithmetic, this one keeps D_h as well conditioned as the stuck
    !> structure's.
    pure subroutine law_stuck_stiffness(law, p, ks)
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: p(:)        !! (npar) the element's parameters
        real(wp), intent(out) :: ks(:)      !! (ndir) N/m
        ks = 0.0_wp
        select case (law)
        case (LAW_JENKINS, LAW_CUBIC)
            ks(1) = abs(p(1))
        case (LAW_NORMAL1D, LAW_NORMAL2D)
            ks(1:size(ks) - 1) = abs(p(1))
            ks(size(ks)) = abs(p(2))
        case (LAW_IWAN4)
            ks(1) = abs(p(2))
        case (LAW_IWAN)
            ks(1) = sum(max(p(1::2), 0.0_wp))
        end select
    end subroutine law_stuck_stiffness

    !> The local force f(ndir) of one element at rest (zero relative displacement): the
    !> normal preload max(n0, 0) of normal1d / normal2d on their normal direction (the
    !> last), zero otherwise (Jenkins' fn0 has no normal direction; the tangential force
    !> at rest depends on the slider, and is left in the harmonics).
    pure subroutine law_rest_force(law, p, f)
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: p(:)        !! (npar) the element's parameters
        real(wp), intent(out) :: f(:)       !! (ndir) N
        f = 0.0_wp
        if (law == LAW_NORMAL1D .or. law == LAW_NORMAL2D) f(size(f)) = max(p(4), 0.0_wp)
    end subroutine law_rest_force

    !> The code of a user law (frirom_user_law): negative, carrying its sizes,
    !> -(ndir + 8 (npar + 256 nslider)) with 1 <= ndir <= 7, 0 <= npar <= 255,
    !> 0 <= nslider <= 1e6 (0 when out of range).
    pure integer(ip) function law_user_code(ndir, npar, nslider)
        integer(ip), intent(in) :: ndir, npar, nslider
        law_user_code = 0
        if (ndir < 1 .or. ndir > 7 .or. npar < 0 .or. npar > 255 .or. nslider < 0 .or. &
            nslider > 1000000) return
        law_user_code = -(ndir + 8*(npar + 256*nslider))
    end function law_user_code

    !> Number of directions of a law (0 for an unknown code).
    pure integer(ip) function law_ndir(law)
        integer(ip), intent(in) :: law
        law_ndir = 0
        if (known(law)) law_ndir = NDIR_OF(law)
        if (law < 0) law_ndir = mod(-law, 8)
    end function law_ndir

    !> Number of parameters per element of a law (0 for an unknown code).
    pure integer(ip) function law_npar(law)
        integer(ip), intent(in) :: law
        law_npar = 0
        if (known(law)) law_npar = NPAR_OF(law)
        if (law < 0) law_npar = mod(-law/8, 256)
    end function law_npar

    !> Number of slider components of a law (0 for an unknown code).
    pure integer(ip) function law_nslider(law)
        integer(ip), intent(in) :: law
        law_nslider = 0
        if (known(law)) law_nslider = NSLIDER_OF(law)
        if (law < 0) law_nslider = -law/2048
    end function law_nslider

    pure logical function known(law)
        integer(ip), intent(in) :: law
        known = law >= 1 .and. law <= NLAW
    end function known

    !> Make the plans for H harmonics and N samples (N >= 2H+1), once per run.
    subroutine aft_plan_create(plan, nharm, nsamp, info, errmsg, measure, nbatch)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: nharm                !! H
        integer(ip), intent(in) :: nsamp                !! N
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        logical, intent(in), optional :: measure        !! FFTW_MEASURE (default FFTW_ESTIMATE)
        integer(ip), intent(in), optional :: nbatch     !! elements per batch (default 16)
        logical :: meas
        integer(ip) :: nb, nc
        ! FFTW_ESTIMATE by default: FFTW_MEASURE times candidate algorithms and may pick a
        ! different one run to run (under another machine load), whose round-off differs,
        ! so the same deck would not give the same points bit for bit.
        meas = .false.
        if (present(measure)) meas = measure
        nb = DEFAULT_BATCH
        if (present(nbatch)) nb = max(1_ip, nbatch)
        call aft_plan_destroy(plan)
        call fourier_plan_create(plan%fp, nharm, nsamp, nb, 3_ip, 6_ip, meas, info, errmsg)
        if (info /= FRIROM_OK) return
        nb = plan%fp%nbatch
        nc = plan%fp%ncoef
        allocate (plan%state(nb, nsamp), plan%tangent(nb, 12, nsamp), plan%par(nb, 4), &
                  plan%follow(nb, nsamp, 2))
        allocate (plan%w(nb, 2), plan%wstart(nb, 2), plan%scale(nb), plan%closed_at(nb))
        allocate (plan%anchor(nb), plan%anchor_state(nb), plan%anchor_dtv(nb), &
                  plan%events(nsamp + 1))
        allocate (plan%dw(2, 3*nc), plan%dw0(2, 3*nc), plan%dft(2, 3*nc), plan%jw(nc, 3), &
                  plan%jt(0:2*nharm, 6))
        allocate (plan%wplain(nb, 2), plan%res_base(nb), &
                  plan%res_last(nb), plan%stepped(nb), plan%accelerated(nb), plan%hold(nb), &
                  plan%damp(nb), plan%damp_cap(nb), plan%held(nb), plan%drifting(nb), &
                  plan%unsettled(nb))
        plan%held = 0
    end subroutine aft_plan_create

    !> Release the plans and work arrays (a destroyed or never created plan is fine).
    subroutine aft_plan_destroy(plan)
        type(aft_plan), intent(inout) :: plan
        call fourier_plan_destroy(plan%fp)
        if (allocated(plan%state)) deallocate (plan%state, plan%par, plan%w, plan%wstart, &
                                                  plan%scale, plan%closed_at)
        if (allocated(plan%anchor)) deallocate (plan%anchor, plan%anchor_state, plan%anchor_dtv, &
                                                   plan%events)
        if (allocated(plan%tangent)) deallocate (plan%tangent, plan%follow)
        if (allocated(plan%dw)) deallocate (plan%dw, plan%dw0, plan%dft, plan%jw, plan%jt)
        if (allocated(plan%wplain)) deallocate (plan%wplain, plan%res_base, plan%res_last, &
                                                plan%stepped, plan%accelerated, plan%hold, &
                                                plan%damp, plan%damp_cap, plan%held, &
                                                plan%drifting, plan%unsettled)
    end subroutine aft_plan_destroy
end module frirom_aft
