!> Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015): the two
!> systems a mode run of frirom_run solves, extensions of frirom_hbm's hbm_system, and
!> their interfaces; the work is in the submodules frirom_hbm_epmc (all DoFs x
!> harmonics, dense Jacobian) and frirom_hbm_epmc_modal (the contact DoFs by modal
!> superposition).
module frirom_epmc
    use frirom_kinds, only: wp, ip
    use frirom_hbm, only: hbm_system
    implicit none
    private
    public :: hbm_epmc, hbm_epmc_set, hbm_epmc_guess, hbm_epmc_jacobian, hbm_epmc_modal, &
              hbm_epmc_modal_set

    !> Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015) on all
    !> DoFs x harmonics: M x'' + (C - xi M) x' + K x + G^T f(G x) = fe0 (harmonic 0, a
    !> static load) with x = X_0 + a sum_h (Xc_h cos + Xs_h sin)(h w t), the parameter
    !> lam = log10 a. Unknowns y = [X (i + ndof (c-1), harmonic 0 unscaled, the others
    !> of the unit modal amplitude), w / w0, xi / w0]; the two equations besides the
    !> harmonic balance (rows of harmonics >= 1 divided by a): Xc_1^T M Xc_1 + Xs_1^T M
    !> Xs_1 = 1 (amplitude) and (M phi)^T Xs_1 = 0 (phase, phi the linear mode it starts
    !> from), both weighted by wn. J dense (LAPACK dgetrf), bordered by the d/dw and
    !> d/dxi columns.
    type, extends(hbm_system) :: hbm_epmc
        integer(ip) :: nf = 0                    !! ndof (2H+1): the harmonics' unknowns
        real(wp) :: w0 = 0.0_wp                  !! rad/s: unit of the w and xi unknowns
        real(wp) :: wn = 1.0_wp                  !! weight of the amplitude, phase rows
        real(wp), allocatable :: phi(:)          !! (ndof) mass-normalised linear mode
        real(wp), allocatable :: pw(:)           !! (ndof) phase weights M phi / |M phi|
        real(wp), allocatable :: jd(:, :)        !! (n, n) LU of J
        integer, allocatable :: ipiv(:)          !! (n) its pivots
        real(wp), allocatable :: jp(:, :)        !! (nf, nf) work: d(D X + F)/dX
        real(wp), allocatable :: xp(:, :)        !! (ndof, nc) work: physical harmonics
        !> eval with jac factorises J (else leaves it in jd: hbm_epmc_jacobian)
        logical :: factor = .true.
    contains
        !> R and dR/dlam (lam = log10 a); with jac, J factorised (dense LU)
        procedure :: eval => epmc_eval
        !> b := J^-1 b with that LU
        procedure :: solve => epmc_solve
        !> the output DoFs' physical harmonics X_0 + a X_h
        procedure :: outputs => epmc_outputs
        !> the contact history of the physical motion
        procedure :: accept => epmc_accept
    end type hbm_epmc

    !> The EPMC condensed to the contact DoFs nl by modal superposition: unknowns y = [U
    !> (j + nnl (c-1): harmonic 0 physical, the others of the unit modal amplitude), w /
    !> w0, xi / w0]; U_h + R_h(w, xi) F_h(U) = 0 with R_h = Phi_nl diag(g_h) Phi_nl^T,
    !> g_rh = 1 / (w_r^2 - (h w)^2 + i h w (2 zeta_r w_r - xi)) (the artificial damping
    !> only changes the modal damping term), R_0 = Phi_nl diag(1/w_r^2) Phi_nl^T; the
    !> modal coordinates q_h = -g_h Phi_nl^T F_h give the amplitude (|q_1|^2 = a^2, Phi
    !> mass-normalised) and the phase (c^T Im q_1 = 0, c = Phi^T M phi). Exact with all
    !> modes; with some, the receptances' truncation.
    type, extends(hbm_system) :: hbm_epmc_modal
        integer(ip) :: nf = 0, nnl = 0, nm = 0
        real(wp) :: w0 = 0.0_wp, wn = 1.0_wp
        integer(ip), allocatable :: nl(:), colmap(:)     !! (nnl), (ndof)
        real(wp), allocatable :: phn(:, :), pho(:, :)    !! (nnl, nm), (nout, nm) shapes
        real(wp), allocatable :: wr(:), zr(:), cph(:)    !! (nm) rad/s, ratios, phase
        real(wp), allocatable :: qst(:)                  !! (nm) Phi^T fe0 (static load)
        real(wp), allocatable :: phi0(:)                 !! (ndof) the linear mode
        real(wp), allocatable :: jd(:, :), jp(:, :)      !! (n, n) LU of J; (nf, nf) dF/dU
        integer, allocatable :: ipiv(:)
        real(wp), allocatable :: fl(:, :)                !! (nnl, nc) forces at nl
        logical :: factor = .true.
    contains
        procedure :: eval => epmd_eval
        procedure :: solve => epmd_solve
        procedure :: outputs => epmd_outputs
        procedure :: accept => epmd_accept
    end type hbm_epmc_modal

    ! ---- frirom_hbm_epmc: nonlinear modes (EPMC) ------------------------------------
    interface
        !> Make a built hbm_epmc ready: the linear mode phi (ndof, mass-normalised by the
        !> caller or here) and its natural frequency w0 (rad/s) it starts from; n = nf + 2.
        module subroutine hbm_epmc_set(sysc, phi, w0, info, errmsg)
            class(hbm_system), intent(inout) :: sysc
            real(wp), intent(in) :: phi(:), w0
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_epmc_set

        !> Make a built hbm_epmc_modal ready: the linear mode phi0 (ndof) and w0 it starts
        !> from, the modes phi (ndof, nm; mass-normalised here) with wm (rad/s > 0) and
        !> zm, and the contact DoFs nl (frirom_hbm_epmc_modal.f90).
        module subroutine hbm_epmc_modal_set(sysc, phi0, w0, phi, wm, zm, nl, info, errmsg)
            class(hbm_system), intent(inout) :: sysc
            real(wp), intent(in) :: phi0(:), w0, phi(:, :), wm(:), zm(:)
            integer(ip), intent(in) :: nl(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_epmc_modal_set

        module subroutine epmd_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
            class(hbm_epmc_modal), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            real(wp), intent(out) :: r(:)
            real(wp), intent(out) :: rref
            logical, intent(in) :: jac
            real(wp), intent(out) :: rlam(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmd_eval

        module subroutine epmd_solve(this, b, info, errmsg)
            class(hbm_epmc_modal), intent(inout) :: this
            real(wp), intent(inout) :: b(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmd_solve

        module subroutine epmd_outputs(this, y, lam, xo, info, errmsg)
            class(hbm_epmc_modal), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmd_outputs

        module subroutine epmd_accept(this, y, lam, info, errmsg)
            class(hbm_epmc_modal), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmd_accept

        !> The start of a mode run: the linear mode in harmonic 1's cosine, w / w0 = 1 and
        !> xi = phi^T C phi (the mode's linear damping).
        module subroutine hbm_epmc_guess(sysc, y)
            class(hbm_system), intent(in) :: sysc
            real(wp), intent(out) :: y(:)     !! (n)
        end subroutine hbm_epmc_guess

        !> The residual r, dR/dlam and the Jacobian jm (n, n) unfactorised at (y, lam) of
        !> a mode run (for checks against finite differences).
        module subroutine hbm_epmc_jacobian(sysc, y, lam, r, rlam, jm, info, errmsg)
            class(hbm_system), intent(inout) :: sysc
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: r(:), rlam(:), jm(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_epmc_jacobian

        module subroutine epmc_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
            class(hbm_epmc), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            real(wp), intent(out) :: r(:)
            real(wp), intent(out) :: rref
            logical, intent(in) :: jac
            real(wp), intent(out) :: rlam(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmc_eval

        module subroutine epmc_solve(this, b, info, errmsg)
            class(hbm_epmc), intent(inout) :: this
            real(wp), intent(inout) :: b(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmc_solve

        module subroutine epmc_outputs(this, y, lam, xo, info, errmsg)
            class(hbm_epmc), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmc_outputs

        module subroutine epmc_accept(this, y, lam, info, errmsg)
            class(hbm_epmc), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine epmc_accept
    end interface
end module frirom_epmc
