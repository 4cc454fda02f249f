!> Harmonic balance equations of M x'' + C x' + K x + G^T f(G x) = f_e in real harmonic
!> form (per DoF: [a0, a1, b1, ..., aH, bH], x = a0 + sum a_h cos(h tau) + b_h sin(h tau)),
!> with their analytical Jacobian, in two formulations that give the same solution:
!>
!> * hbm_condensed (Eq. 5-9 of the reference): unknowns are the harmonics of the nonlinear
!>   DoFs only (column support of all G), R = X_n - X_e,n + H_nn F_c(X_n), receptances from
!>   a banded factorisation of D_h = K + i h w C - (h w)^2 M per harmonic, refreshed only
!>   when the frequency changes; J = I + H_nn dF_c/dX_n (dense LU). Outputs by Eq. 9.
!> * hbm_full: all DoFs x harmonics, R = D X + F_c(X) - F_e, unknowns ordered DoF by DoF in
!>   a reverse Cuthill-McKee order so that J is banded (LAPACK dgbtrf).
!>
!> The parameter lam is the frequency w (mode 1, excitation fe0) or a load factor (mode 2,
!> excitation fe0 + lam fe1 at the fixed frequency omega_fix). Contact groups go through
!> the AFT kernel (frirom_aft) with one plan made when the system is built.
!> K, M and C must be symmetric (the condensed dR/dw uses D_h^T = D_h). The condensed
!> receptances may instead come from modes: the same real modes for every harmonic
!> (hbm_set_modes) or complex modes of their own per harmonic (hbm_set_modes_harmonic, a
!> cyclic sector whose harmonic h lives on nodal diameter h EO mod N); K, M, C are then
!> not used and may be empty.
!>
!> The module holds the types, the named constants and the interfaces; the work is done in
!> its submodules, one file each:
!>   frirom_hbm_contacts.f90   CSR helpers, contact set (contact_eval, contact_assemble),
!>                             sliders and the accept step
!>   frirom_hbm_condensed.f90  condensed formulation (Eq. 5-9): receptances, modal
!>                             receptances, residual/Jacobian, outputs (Eq. 9)
!>   frirom_hbm_full.f90       full banded formulation
!>   frirom_hbm_hill.f90       Hill stability (Floquet exponents)
!>   frirom_hbm_run.f90        hbm_setup and the run driver hbm_run
module frirom_hbm
    use frirom_kinds, only: wp, ip
    use frirom_banded, only: band_matrix, zband_matrix
    use frirom_newton, only: nl_system, cont_options
    use frirom_aft, only: aft_plan
    ! Explicit LAPACK/BLAS interfaces for every call the submodules make.
    use frirom_lapack, only: dgemm, zgemm, dgetrf, dgetrs, dgeev, dpotrf, dpotrs
    implicit none
    private
    public :: csr_matrix, contact_group, contact_set, hbm_system, hbm_condensed, hbm_full, &
              hbm_setup, hbm_set_modes, hbm_set_modes_harmonic, hbm_run, hbm_hill, &
              hbm_sliders, contact_eval, contact_assemble, &
              HBM_FREQUENCY, HBM_LOAD, &
              HBM_START_CONTINUE, HBM_START_RESUME, HBM_START_SOLVE_ONLY, &
              T_AFT, T_ASM, T_FACT, T_SOLVE, T_REC, N_EVAL, N_FACT, N_TIMERS

    !> What lam is: the frequency w (excitation fe0) or a load factor (fe0 + lam fe1 at
    !> the fixed frequency omega_fix).
    integer(ip), parameter :: HBM_FREQUENCY = 1, HBM_LOAD = 2
    !> hbm_run's start_mode: solve at fixed lam from y, then continue; continue from the
    !> converged point (y, lam) with its tangent; only solve at fixed lam.
    integer(ip), parameter :: HBM_START_CONTINUE = 0, HBM_START_RESUME = 1, &
                              HBM_START_SOLVE_ONLY = 2
    !> Indices of the timers/counters in hbm_system%timers: AFT, Jacobian assembly,
    !> factorisation, solves, receptances (s); residual evaluations, factorisations.
    integer(ip), parameter :: T_AFT = 1, T_ASM = 2, T_FACT = 3, T_SOLVE = 4, T_REC = 5, &
                              N_EVAL = 6, N_FACT = 7, N_TIMERS = 8

    !> Sparse matrix in compressed sparse row form, 1-based.
    type :: csr_matrix
        integer(ip) :: nrow = 0, ncol = 0
        integer(ip), allocatable :: p(:)   !! (nrow+1) row pointers
        integer(ip), allocatable :: i(:)   !! (nnz) column indices
        real(wp), allocatable :: x(:)      !! (nnz) values
    end type csr_matrix

    !> One group of contact elements with the same law, and its AFT workspaces.
    type :: contact_group
        integer(ip) :: law = 0, ne = 0, ndir = 0, row0 = 0  !! row0: rows before it in G
        real(wp), allocatable :: params(:, :)   !! (npar, ne)
        real(wp), allocatable :: w0(:, :)       !! (nslider, ne)
        real(wp), allocatable :: x(:, :, :)     !! (nc, ndir, ne) local displacements
        real(wp), allocatable :: f(:, :, :)     !! (nc, ndir, ne) local forces
        real(wp), allocatable :: jac(:, :, :)   !! (nc ndir, nc ndir, ne)
        real(wp), allocatable :: states(:, :)   !! (3, ne) stick, slip, lift-off fractions
    end type contact_group

    !> All contact groups; G maps the model's columns (full DoFs or nonlinear DoFs) to the
    !> local relative displacements, rows group by group, element by element, direction.
    type :: contact_set
        integer(ip) :: nc = 0
        type(csr_matrix) :: g
        type(contact_group), allocatable :: grp(:)
    end type contact_set

    !> Data shared by both formulations.
    type, abstract, extends(nl_system) :: hbm_system
        integer(ip) :: ndof = 0, nh = 0, nc = 0, mode = HBM_FREQUENCY
        real(wp) :: omega_fix = 0.0_wp
        type(csr_matrix) :: k, m, c
        integer(ip), allocatable :: perm(:), iperm(:)   !! RCM order of the DoFs
        integer(ip) :: bw = 0                           !! DoF half-bandwidth under perm
        real(wp), allocatable :: fe0(:, :), fe1(:, :)   !! (ndof, nc) excitation, load part
        integer(ip), allocatable :: outdofs(:)          !! output DoFs
        type(contact_set) :: cs
        type(aft_plan) :: plan
        !> (ncol, nc) work: harmonics of G's columns (nonlinear DoFs of a condensed
        !> system, all DoFs of a full one) and the contact forces on them
        real(wp), allocatable :: xd(:, :), fd(:, :)
        real(wp) :: timers(N_TIMERS) = 0.0_wp
        !> accept carries the contact history (sliders) from point to point; .false.
        !> restarts every AFT call from the w0 given at setup
        logical :: carry = .true.
    contains
        procedure(outputs_iface), deferred :: outputs
        procedure :: accept => hbm_accept
    end type hbm_system

    abstract interface
        !> Harmonics xo(nout, nc) at the output DoFs for a solution y at lam (after an eval
        !> at that point).
        subroutine outputs_iface(this, y, lam, xo, info, errmsg)
            import :: hbm_system, wp, ip
            class(hbm_system), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine outputs_iface
    end interface

    !> Condensed formulation: y(j + nnl (c-1)) = harmonic coefficient c of nonlinear DoF j.
    type, extends(hbm_system) :: hbm_condensed
        integer(ip) :: nnl = 0
        integer(ip), allocatable :: nl(:)                !! (nnl) nonlinear DoFs
        real(wp) :: w_cache = -1.0_wp
        type(zband_matrix) :: d                          !! work: D_h, banded, RCM order
        complex(wp), allocatable :: ymat(:, :, :)        !! (ndof, nnl, 0:nh) D_h^-1 P^T
        complex(wp), allocatable :: ye0(:, :), ye1(:, :) !! (ndof, 0:nh) D_h^-1 fe
        real(wp), allocatable :: ar(:, :, :), ai(:, :, :) !! (nnl, nnl, 0:nh) Re, Im H_nn
        real(wp), allocatable :: kc(:, :), jm(:, :)      !! (n, n) contact Jacobian, J
        integer(ip), allocatable :: ipiv(:)
        !> modal superposition instead of factorising D_h (hbm_set_modes, or
        !> hbm_set_modes_harmonic: modes of their own for every harmonic)
        logical :: modal = .false.
        !> (nr) DoFs where psi is kept: the nl DoFs first (rows 1..nnl), then the other
        !> output DoFs
        integer(ip), allocatable :: mrow(:)
        complex(wp), allocatable :: psi(:, :, :)         !! (nr, nm, 0:nh) mode shapes
        real(wp), allocatable :: wm(:, :), zm(:, :)      !! (nm, 0:nh) rad/s, damping ratios
        complex(wp), allocatable :: dg(:, :)             !! (nm, 0:nh) d g_r / d w
        complex(wp), allocatable :: qf(:, :), qf1(:, :)  !! (nm, 0:nh) Psi_h^H fe0_h, fe1_h
    contains
        procedure :: eval => cond_eval
        procedure :: solve => cond_solve
        procedure :: outputs => cond_outputs
    end type hbm_condensed

    !> Full banded formulation: y(c + nc (iperm(i)-1)) = coefficient c of DoF i.
    type, extends(hbm_system) :: hbm_full
        type(band_matrix) :: jb
        real(wp), allocatable :: rd(:, :)  !! (ndof, nc) residual by DoF
    contains
        procedure :: eval => full_eval
        procedure :: solve => full_solve
        procedure :: outputs => full_outputs
    end type hbm_full

    ! ---- frirom_hbm_contacts: CSR helpers and the contact set ---------------------------
    interface
        !> Check and copy a CSR matrix (nrow x ncol, 1-based).
        module subroutine csr_set(a, nrow, ncol, p, i, x, name, info, errmsg)
            type(csr_matrix), intent(out) :: a
            integer(ip), intent(in) :: nrow, ncol, p(:), i(:)
            real(wp), intent(in) :: x(:)
            character(len=*), intent(in) :: name
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine csr_set

        !> Forces fd(ncol, nc) = G^T f(G xd) of all contact groups, and their local
        !> Jacobians (kept in the groups) when jac is true. With carry, each group's w0
        !> becomes the slider its closed cycle at xd starts with (the history the next
        !> point inherits).
        module subroutine contact_eval(cs, plan, xd, fd, jac, info, errmsg, carry)
            type(contact_set), intent(inout) :: cs
            type(aft_plan), intent(inout) :: plan
            real(wp), intent(in) :: xd(:, :)    !! (ncol, nc) harmonics of the columns
            real(wp), intent(out) :: fd(:, :)   !! (ncol, nc) contact forces on the columns
            logical, intent(in) :: jac
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            logical, intent(in), optional :: carry
        end subroutine contact_eval

        !> Add G^T J_loc G (from the last contact_eval with jac) to a dense matrix kd,
        !> index col + ncol (c-1), or to a banded matrix kb, index c + nc (iperm(col)-1).
        module subroutine contact_assemble(cs, kd, kb, iperm, info, errmsg, colmap, ldc)
            type(contact_set), intent(in) :: cs
            real(wp), intent(inout), optional :: kd(:, :)
            type(band_matrix), intent(inout), optional :: kb
            integer(ip), intent(in), optional :: iperm(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            integer(ip), intent(in), optional :: colmap(:)  !! dense: column -> index
            integer(ip), intent(in), optional :: ldc        !! dense: harmonic stride
        end subroutine contact_assemble

        !> The contact forces at the solution y of either formulation: sys%xd = the
        !> harmonics of G's columns in y, sys%fd = G^T f(G xd) (contact_eval with jac and
        !> carry). timed: count it as a residual evaluation and time it as AFT.
        module subroutine hbm_contact_forces(sys, y, jac, info, errmsg, carry, timed)
            class(hbm_system), intent(inout) :: sys
            real(wp), intent(in) :: y(:)
            logical, intent(in) :: jac
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            logical, intent(in), optional :: carry, timed
        end subroutine hbm_contact_forces

        !> Accept a converged point: every contact group's initial slider becomes the
        !> slider of the closed cycle at y, so the following points continue from this
        !> point's contact history (a contact entering stick-all-cycle keeps the slider
        !> where it last slipped). Within one corrector w0 stays fixed, so R(y) and its
        !> Jacobian stay consistent.
        module subroutine hbm_accept(this, y, lam, info, errmsg)
            class(hbm_system), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_accept

        !> The initial sliders of all groups, (nslider, ne) per group concatenated (the
        !> layout of hbm_setup's w0); w must hold at least that many values, the rest is
        !> left alone.
        module subroutine hbm_sliders(sys, w)
            class(hbm_system), intent(in) :: sys
            real(wp), intent(inout) :: w(:)
        end subroutine hbm_sliders
    end interface

    !> y += alpha A x for the columns of x (A real, in CSR); x, y and alpha real or
    !> complex (the complex case runs the real kernel on the real and imaginary parts).
    interface csr_matvec_add
        pure module subroutine csr_matvec_add_real(a, x, y, alpha)
            type(csr_matrix), intent(in) :: a
            real(wp), intent(in) :: x(:)
            real(wp), intent(inout) :: y(:)
            real(wp), intent(in) :: alpha
        end subroutine csr_matvec_add_real
        pure module subroutine csr_matvec_add_cplx(a, x, y, alpha)
            type(csr_matrix), intent(in) :: a
            complex(wp), intent(in) :: x(:)
            complex(wp), intent(inout) :: y(:)
            complex(wp), intent(in) :: alpha
        end subroutine csr_matvec_add_cplx
    end interface csr_matvec_add

    ! ---- frirom_hbm_condensed: Eq. 5-9 ---------------------------------------------------
    interface
        !> Sizes and allocates the condensed system's receptances and Jacobian.
        module subroutine cond_init(sys, nl, info, errmsg)
            type(hbm_condensed), intent(inout) :: sys
            integer(ip), intent(in) :: nl(:)       !! (nnl) nonlinear DoFs, sorted
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_init

        !> Use modal superposition for the receptances of a condensed system:
        !> H_h = Phi diag(1 / (w_r^2 - (h w)^2 + 2 i zeta_r w_r h w)) Phi^T over the given
        !> mass-normalised modes (truncated set: no residual flexibility).
        module subroutine hbm_set_modes(sysc, phi, wm, zm, info, errmsg)
            class(hbm_system), intent(inout), target :: sysc  !! must be an hbm_condensed
            real(wp), intent(in) :: phi(:, :)   !! (ndof, nm)
            real(wp), intent(in) :: wm(:), zm(:) !! (nm) natural frequencies rad/s, ratios
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_set_modes

        !> Modal superposition with modes of their own for every harmonic h:
        !> H_h = Psi_h diag(1 / (w_hr^2 - (h w)^2 + 2 i zeta_hr w_hr h w)) Psi_h^H. A cyclic
        !> sector under an engine-order excitation is such a system: harmonic h lives on
        !> the nodal diameter h EO mod N, with complex mode shapes of that diameter. Modes
        !> with psi = 0 pad harmonics that have fewer modes.
        module subroutine hbm_set_modes_harmonic(sysc, psi, wm, zm, info, errmsg)
            class(hbm_system), intent(inout), target :: sysc  !! must be an hbm_condensed
            complex(wp), intent(in) :: psi(:, :, 0:)  !! (ndof, nm, 0:nh) mode shapes
            real(wp), intent(in) :: wm(:, 0:), zm(:, 0:) !! (nm, 0:nh) rad/s, damping ratios
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_set_modes_harmonic

        !> R = X_n - X_e,n + H_nn F_c(X_n) and dR/dlam; with jac, J = I + H_nn dF_c/dX_n
        !> factorised (dense LU).
        module subroutine cond_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
            class(hbm_condensed), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            real(wp), intent(out) :: r(:)
            real(wp), intent(out) :: rref
            logical, intent(in) :: jac
            real(wp), intent(out) :: rlam(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_eval

        !> b := J^-1 b with the LU of the last cond_eval with jac.
        module subroutine cond_solve(this, b, info, errmsg)
            class(hbm_condensed), intent(inout) :: this
            real(wp), intent(inout) :: b(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_solve

        !> Eq. 9: x_o = rows o of D_h^-1 (fe - P^T fc), from the cached receptance columns.
        module subroutine cond_outputs(this, y, lam, xo, info, errmsg)
            class(hbm_condensed), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine cond_outputs
    end interface

    ! ---- frirom_hbm_full: the full banded formulation -----------------------------------
    interface
        !> Sizes and allocates the banded Jacobian (half-bandwidth nc (bw+1) - 1).
        module subroutine full_init(sys, info, errmsg)
            type(hbm_full), intent(inout) :: sys
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine full_init

        !> R = D X + F_c(X) - F_e and dR/dlam; with jac, J factorised in band form.
        module subroutine full_eval(this, y, lam, r, rref, jac, rlam, info, errmsg)
            class(hbm_full), intent(inout) :: this
            real(wp), intent(in) :: y(:)
            real(wp), intent(in) :: lam
            real(wp), intent(out) :: r(:)
            real(wp), intent(out) :: rref
            logical, intent(in) :: jac
            real(wp), intent(out) :: rlam(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine full_eval

        !> b := J^-1 b with the band LU of the last full_eval with jac.
        module subroutine full_solve(this, b, info, errmsg)
            class(hbm_full), intent(inout) :: this
            real(wp), intent(inout) :: b(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine full_solve

        !> The output DoFs' harmonics, read from y.
        module subroutine full_outputs(this, y, lam, xo, info, errmsg)
            class(hbm_full), intent(inout) :: this
            real(wp), intent(in) :: y(:), lam
            real(wp), intent(out) :: xo(:, :)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine full_outputs
    end interface

    ! ---- frirom_hbm_hill: stability -----------------------------------------------------
    interface
        !> Floquet exponents of the periodic solution y at lam by Hill's method: the
        !> quadratic eigenproblem (J + s D1 + s^2 M) p = 0 over all DoFs x harmonics
        !> (J = dR/dX of the full equations, D1 = C + 2 M d/dt), linearised to a 2n
        !> standard eigenproblem (dense, dgeev). Of the 2n(2H+1) eigenvalues, the 2 ndof
        !> with the smallest |Im s| are the physically meaningful exponents (the others
        !> repeat them shifted by i h w). maxre: their largest real part; the solution is
        !> stable when maxre <= 0.
        module subroutine hbm_hill(sys, y, lam, expo, maxre, info, errmsg)
            class(hbm_system), intent(inout) :: sys
            real(wp), intent(in) :: y(:), lam
            complex(wp), intent(out) :: expo(:)   !! (2 ndof) selected exponents, 1/s
            real(wp), intent(out) :: maxre        !! max real part of expo, 1/s
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_hill
    end interface

    ! ---- frirom_hbm_run: setup, driver and the helpers every formulation uses -----------
    interface
        !> Build a system (condensed or full) from plain arrays; see frirom_f2py
        !> hbm_continue for the meaning of each argument. `nl` is used by the condensed
        !> formulation only.
        module subroutine hbm_setup(sys, nh, nsamp, ndof, kp, ki, kx, mp, mi, mx, cp, ci, &
                                    cx, perm, nl, fe0, fe1, mode, omega_fix, ginfo, gp, gi, &
                                    gx, params, w0, outdofs, info, errmsg)
            class(hbm_system), intent(inout) :: sys
            integer(ip), intent(in) :: nh, nsamp, ndof
            integer(ip), intent(in) :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:)
            real(wp), intent(in) :: kx(:), mx(:), cx(:)
            integer(ip), intent(in) :: perm(:)       !! (ndof) RCM order of the DoFs
            integer(ip), intent(in) :: nl(:)         !! (nnl) nonlinear DoFs, sorted
            real(wp), intent(in) :: fe0(:, :), fe1(:, :)  !! (ndof, 2nh+1)
            integer(ip), intent(in) :: mode
            real(wp), intent(in) :: omega_fix
            integer(ip), intent(in) :: ginfo(:, :)   !! (3, ngroup): law, ne, ndir
            integer(ip), intent(in) :: gp(:), gi(:)  !! G in CSR over the full DoFs
            real(wp), intent(in) :: gx(:)
            real(wp), intent(in) :: params(:)        !! (npar, ne) per group, concatenated
            real(wp), intent(in) :: w0(:)            !! (nslider, ne) per group, concatenated
            integer(ip), intent(in) :: outdofs(:)
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
        end subroutine hbm_setup

        !> Solve and continue (start_mode HBM_START_*): solve at fixed lam from y then
        !> continue, continue from the converged point (y, lam) with tangent t, or only
        !> solve at fixed lam. Each point stores y, lam, tangent, Newton iterations,
        !> output harmonics and contact state fractions. On a failure every point already
        !> made is kept (npts).
        module subroutine hbm_run(sys, start_mode, y, lam, t, ds, lam_lo, opts, ys, lams, &
                                  tans, iters, xo, states, npts, finished, info, errmsg, &
                                  hill_re, sliders)
            class(hbm_system), intent(inout) :: sys
            integer(ip), intent(in) :: start_mode
            real(wp), intent(inout) :: y(:), lam, t(:), ds
            real(wp), intent(in) :: lam_lo
            type(cont_options), intent(in) :: opts
            real(wp), intent(out) :: ys(:, :)        !! (n, maxpts)
            real(wp), intent(out) :: lams(:)         !! (maxpts)
            real(wp), intent(out) :: tans(:, :)      !! (n+1, maxpts)
            integer(ip), intent(out) :: iters(:)     !! (maxpts)
            real(wp), intent(out) :: xo(:, :, :)     !! (nout, nc, maxpts)
            real(wp), intent(out) :: states(:, :, :) !! (3, ne_total, maxpts)
            integer(ip), intent(out) :: npts
            logical, intent(out) :: finished
            integer(ip), intent(out) :: info
            character(len=*), intent(inout) :: errmsg
            real(wp), intent(out), optional :: hill_re(:)  !! (maxpts) max Re of the
                                                           !! Floquet exponents
            real(wp), intent(inout), optional :: sliders(:, :)  !! (nw, maxpts) the contact
                                    !! history each point leaves (hbm_sliders layout)
        end subroutine hbm_run

        !> Wall-clock seconds.
        module function wtime() result(t)
            real(wp) :: t
        end function wtime

        !> Frequency w and load factor s of the excitation at parameter lam.
        pure module subroutine freq_load(sys, lam, w, s)
            class(hbm_system), intent(in) :: sys
            real(wp), intent(in) :: lam
            real(wp), intent(out) :: w, s
        end subroutine freq_load
    end interface
end module frirom_hbm
