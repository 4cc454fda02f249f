!> Nonlinear modes of frirom_hbm by the extended periodic motion concept (EPMC; M. Krack,
!> J. Sound Vib. 338 (2015) 90-104): the harmonic balance of M x'' + (C - xi M) x' + K x +
!> G^T f(G x) = fe0 (static part) on all DoFs, the artificial damping xi making the
!> nonconservative motion periodic. The amplitude a is the parameter (lam = log10 a), the
!> harmonics >= 1 are those of the unit modal amplitude (harmonic 1 mass-normalised), and
!> the phase is fixed against the linear mode the run starts from. See hbm_epmc.
submodule (frirom_epmc) frirom_hbm_epmc
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, &
                             FRIROM_ERR_SINGULAR, FRIROM_ERR_LAPACK, set_status
    use frirom_lapack, only: dgetrf, dgetrs
    use frirom_csr, only: csr_matvec_add
    use frirom_hbm, only: contact_assemble, contact_eval, wtime, T_AFT, T_ASM, T_FACT, &
                          T_SOLVE, N_EVAL, N_FACT
    implicit none

    real(wp), parameter :: LN10 = log(10.0_wp)

contains

    module procedure hbm_epmc_set
        real(wp), allocatable :: mphi(:)
        integer(ip) :: nd
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_epmc)
            nd = sys%ndof
            if (sys%nh < 1) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: harmonics '// &
                                '>= 1 expected')
                return
            end if
            if (size(phi) /= nd .or. .not. all(abs(phi) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'nonlinear mode: phi, a '// &
                                'finite shape of ndof entries expected')
                return
            end if
            if (.not. (w0 > 0.0_wp .and. w0 <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: omega0, '// &
                                'the linear natural frequency (rad/s > 0) expected')
                return
            end if
            call epmc_normalise(sys%m, phi, 'phi', sys%phi, mphi, info, errmsg)
            if (info /= 0) return
            sys%pw = mphi/norm2(mphi)
            sys%w0 = w0
            sys%wn = w0**2*norm2(mphi)
            sys%nf = nd*sys%nc
            sys%n = sys%nf + 2
            if (allocated(sys%jd)) deallocate (sys%jd, sys%ipiv, sys%jp, sys%xp)
            allocate (sys%jd(sys%n, sys%n), sys%ipiv(sys%n), sys%jp(sys%nf, sys%nf), &
                      sys%xp(nd, sys%nc))
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: the run is '// &
                            'not a mode run (mode 3)')
        end select
    end procedure hbm_epmc_set

    module procedure hbm_epmc_guess
        real(wp), allocatable :: cphi(:)
        y = 0.0_wp
        select type (sys => sysc)
        type is (hbm_epmc)
            if (.not. allocated(sys%phi)) return
            allocate (cphi(sys%ndof))
            cphi = 0.0_wp
            call csr_matvec_add(sys%c, sys%phi, cphi, 1.0_wp)
            y(sys%ndof + 1:2*sys%ndof) = sys%phi
            y(sys%nf + 1) = 1.0_wp
            y(sys%nf + 2) = dot_product(sys%phi, cphi)/sys%w0
        type is (hbm_epmc_modal)
            if (.not. allocated(sys%phi0)) return
            allocate (cphi(sys%ndof))
            cphi = 0.0_wp
            call csr_matvec_add(sys%c, sys%phi0, cphi, 1.0_wp)
            y(sys%nnl + 1:2*sys%nnl) = sys%phi0(sys%nl)
            y(sys%nf + 1) = 1.0_wp
            y(sys%nf + 2) = dot_product(sys%phi0, cphi)/sys%w0
        end select
    end procedure hbm_epmc_guess

    module procedure hbm_epmc_jacobian
        real(wp) :: rref
        info = FRIROM_OK
        r = 0.0_wp
        rlam = 0.0_wp
        jm = 0.0_wp
        select type (sys => sysc)
        class is (epmc_system)
            if (size(y) /= sys%n .or. size(r) /= sys%n .or. size(rlam) /= sys%n .or. &
                any(shape(jm) /= [sys%n, sys%n])) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_epmc_jacobian: y, r, '// &
                                'rlam (n) and jm (n, n) expected')
                return
            end if
            sys%factor = .false.
            call sys%eval(y, lam, r, rref, .true., rlam, info, errmsg)
            sys%factor = .true.
            if (info == 0) jm = sys%jd
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_epmc_jacobian: not a '// &
                            'mode run')
        end select
    end procedure hbm_epmc_jacobian

    !> The physical harmonics xp (ndof, nc) of y at amplitude a.
    pure subroutine physical(nd, nc, y, a, xp)
        integer(ip), intent(in) :: nd, nc
        real(wp), intent(in) :: y(:), a
        real(wp), intent(out) :: xp(:, :)
        xp = reshape(y(1:nd*nc), [nd, nc])
        xp(:, 2:) = a*xp(:, 2:)
    end subroutine physical

    module procedure epmc_normalise
        real(wp) :: mn
        info = FRIROM_OK
        allocate (mphin(size(phi)))
        mphin = 0.0_wp
        call csr_matvec_add(m, phi, mphin, 1.0_wp)
        mn = dot_product(phi, mphin)
        if (.not. (mn > 0.0_wp)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode: '//what// &
                            ' has no mass (phi^T M phi <= 0)')
            return
        end if
        phin = phi/sqrt(mn)
        mphin = mphin/sqrt(mn)
    end procedure epmc_normalise

    module procedure epmc_unpack
        info = FRIROM_OK
        a = 10.0_wp**lam
        w = this%w0*y(this%nf + 1)
        xi = this%w0*y(this%nf + 2)
        if (.not. allocated(this%jd)) call set_status(info, FRIROM_ERR_PARAM, errmsg, &
            'nonlinear mode: no linear mode set (run_set_nonlinear_mode)')
    end procedure epmc_unpack

    module procedure epmc_eval
        real(wp) :: a, w, xi, hw, t0, nlin, nfc
        real(wp), allocatable :: rl(:, :), dw(:, :), dx(:, :), yd(:)
        integer(ip) :: nd, nc, nf, h, ca, cb, c
        call epmc_unpack(this, y, lam, a, w, xi, info, errmsg)
        if (info /= 0) return
        nd = this%ndof
        nc = this%nc
        nf = this%nf
        call physical(nd, nc, y, a, this%xp)
        this%xd = this%xp
        t0 = wtime()
        call contact_eval(this%cs, this%plan, this%xd, this%fd, .true., info, errmsg)
        this%timers(T_AFT) = this%timers(T_AFT) + wtime() - t0
        this%timers(N_EVAL) = this%timers(N_EVAL) + 1
        if (info /= 0) return
        ! the linear part on the unit-amplitude harmonics (rows >= 1 divided by a), its
        ! derivatives in w / w0 (dw) and xi / w0 (dx)
        allocate (rl(nd, nc), dw(nd, nc), dx(nd, nc))
        rl = 0.0_wp
        dw = 0.0_wp
        dx = 0.0_wp
        associate (yh => reshape(y(1:nf), [nd, nc]))
            call madd(this%k, yh, rl, 1.0_wp)
            do h = 1, this%nh
                hw = h*w
                ca = 2*h
                cb = 2*h + 1
                call madd(this%m, yh(:, ca:cb), rl(:, ca:cb), -hw*hw)
                call csr_matvec_add(this%c, yh(:, cb), rl(:, ca), hw)
                call csr_matvec_add(this%c, yh(:, ca), rl(:, cb), -hw)
                call csr_matvec_add(this%m, yh(:, cb), rl(:, ca), -hw*xi)
                call csr_matvec_add(this%m, yh(:, ca), rl(:, cb), hw*xi)
                ! d/dw: -2 h^2 w M X + h (C - xi M) (Xs, -Xc)
                call madd(this%m, yh(:, ca:cb), dw(:, ca:cb), -2.0_wp*h*hw)
                call csr_matvec_add(this%c, yh(:, cb), dw(:, ca), real(h, wp))
                call csr_matvec_add(this%c, yh(:, ca), dw(:, cb), -real(h, wp))
                call csr_matvec_add(this%m, yh(:, cb), dw(:, ca), -h*xi)
                call csr_matvec_add(this%m, yh(:, ca), dw(:, cb), h*xi)
                ! d/dxi: h w M (-Xs, Xc)
                call csr_matvec_add(this%m, yh(:, cb), dx(:, ca), -hw)
                call csr_matvec_add(this%m, yh(:, ca), dx(:, cb), hw)
            end do
            nlin = norm2(rl)
            nfc = norm2(this%fd(:, 1)) + norm2(this%fd(:, 2:))/a
            rl(:, 1) = rl(:, 1) + this%fd(:, 1) - this%fe0(:, 1)
            rl(:, 2:) = rl(:, 2:) + this%fd(:, 2:)/a
            r(1:nf) = reshape(rl, [nf])
            r(nf + 1) = this%wn*(sum(yh(:, 2)*mv(this%m, yh(:, 2))) + &
                                 sum(yh(:, 3)*mv(this%m, yh(:, 3))) - 1.0_wp)
            r(nf + 2) = this%wn*dot_product(this%pw, yh(:, 3))
            rref = max(nlin, nfc, norm2(this%fe0(:, 1)), this%wn)
            if (allocated(this%cs%c0)) rref = max(rref, norm2(this%cs%c0))
            this%rref_dyn = -1.0_wp
            ! d(D X + F)/dX (physical), then scaled to the unknowns: rows >= 1 / a,
            ! columns >= 1 * a
            t0 = wtime()
            this%jp = 0.0_wp
            do c = 1, nc
                call dense_add(this%jp, this%k, nd, c, c, 1.0_wp)
            end do
            do h = 1, this%nh
                hw = h*w
                ca = 2*h
                cb = 2*h + 1
                call dense_add(this%jp, this%m, nd, ca, ca, -hw*hw)
                call dense_add(this%jp, this%m, nd, cb, cb, -hw*hw)
                call dense_add(this%jp, this%c, nd, ca, cb, hw)
                call dense_add(this%jp, this%c, nd, cb, ca, -hw)
                call dense_add(this%jp, this%m, nd, ca, cb, -hw*xi)
                call dense_add(this%jp, this%m, nd, cb, ca, hw*xi)
            end do
            call contact_assemble(this%cs, kd=this%jp, info=info, errmsg=errmsg)
            if (info /= 0) return
            this%jp(nd + 1:, 1:nd) = this%jp(nd + 1:, 1:nd)/a
            this%jp(1:nd, nd + 1:) = this%jp(1:nd, nd + 1:)*a
            ! dR/dlam = ln 10 (J [0; X_dyn] - [0; R_dyn])
            allocate (yd(nf))
            yd = y(1:nf)
            yd(1:nd) = 0.0_wp
            rlam(1:nf) = matmul(this%jp, yd)
            rlam(nd + 1:nf) = rlam(nd + 1:nf) - r(nd + 1:nf)
            rlam(1:nf) = LN10*rlam(1:nf)
            rlam(nf + 1:) = 0.0_wp
            this%timers(T_ASM) = this%timers(T_ASM) + wtime() - t0
            if (.not. jac) return
            t0 = wtime()
            this%jd = 0.0_wp
            this%jd(1:nf, 1:nf) = this%jp
            this%jd(1:nf, nf + 1) = this%w0*reshape(dw, [nf])
            this%jd(1:nf, nf + 2) = this%w0*reshape(dx, [nf])
            this%jd(nf + 1, nd + 1:2*nd) = 2.0_wp*this%wn*mv(this%m, yh(:, 2))
            this%jd(nf + 1, 2*nd + 1:3*nd) = 2.0_wp*this%wn*mv(this%m, yh(:, 3))
            this%jd(nf + 2, 2*nd + 1:3*nd) = this%wn*this%pw
        end associate
        this%timers(T_ASM) = this%timers(T_ASM) + wtime() - t0
        if (.not. this%factor) return
        call epmc_factor(this, info, errmsg)
    end procedure epmc_eval

    !> y(:, k) += alpha A x(:, k) for every column k.
    subroutine madd(a, x, y, alpha)
        type(csr_matrix), intent(in) :: a
        real(wp), intent(in) :: x(:, :)
        real(wp), intent(inout) :: y(:, :)
        real(wp), intent(in) :: alpha
        integer(ip) :: k
        do k = 1, size(x, 2)
            call csr_matvec_add(a, x(:, k), y(:, k), alpha)
        end do
    end subroutine madd

    !> M v.
    function mv(m, v) result(u)
        type(csr_matrix), intent(in) :: m
        real(wp), intent(in) :: v(:)
        real(wp) :: u(size(v))
        u = 0.0_wp
        call csr_matvec_add(m, v, u, 1.0_wp)
    end function mv

    !> jp(block rc, block cc) += alpha A, block c holding the DoFs of coefficient c.
    subroutine dense_add(jp, a, nd, rc, cc, alpha)
        real(wp), intent(inout) :: jp(:, :)
        type(csr_matrix), intent(in) :: a
        integer(ip), intent(in) :: nd, rc, cc
        real(wp), intent(in) :: alpha
        integer(ip) :: i, k, r0, c0
        r0 = nd*(rc - 1)
        c0 = nd*(cc - 1)
        do i = 1, a%nrow
            do k = a%p(i), a%p(i + 1) - 1
                jp(r0 + i, c0 + a%i(k)) = jp(r0 + i, c0 + a%i(k)) + alpha*a%x(k)
            end do
        end do
    end subroutine dense_add


    module procedure epmc_solve
        real(wp) :: t0
        integer :: linfo
        info = FRIROM_OK
        t0 = wtime()
        call dgetrs('N', this%n, size(b, 2), this%jd, this%n, this%ipiv, b, size(b, 1), linfo)
        this%timers(T_SOLVE) = this%timers(T_SOLVE) + wtime() - t0
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrs: illegal '// &
                                        'argument')
    end procedure epmc_solve

    module procedure epmc_factor
        real(wp) :: t0
        integer :: linfo
        info = FRIROM_OK
        t0 = wtime()
        call dgetrf(this%n, this%n, this%jd, this%n, this%ipiv, linfo)
        this%timers(T_FACT) = this%timers(T_FACT) + wtime() - t0
        this%timers(N_FACT) = this%timers(N_FACT) + 1
        if (linfo > 0) then
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'nonlinear mode: dgetrf '// &
                            'zero pivot (singular Jacobian)')
        else if (linfo < 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgetrf: illegal argument')
        end if
    end procedure epmc_factor

    module procedure epmc_outputs
        integer(ip) :: j
        info = FRIROM_OK
        call physical(this%ndof, this%nc, y, 10.0_wp**lam, this%xp)
        do j = 1, size(this%outdofs)
            xo(j, :) = this%xp(this%outdofs(j), :)
        end do
        if (.false.) errmsg = ''
    end procedure epmc_outputs

    module procedure epmc_accept
        info = FRIROM_OK
        if (size(this%cs%grp) == 0 .or. .not. this%carry) return
        call physical(this%ndof, this%nc, y, 10.0_wp**lam, this%xp)
        this%xd = this%xp
        call contact_eval(this%cs, this%plan, this%xd, this%fd, .false., info, errmsg, &
                          carry=.true.)
    end procedure epmc_accept
end submodule frirom_hbm_epmc
