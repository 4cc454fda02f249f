!> Modal damping of a dense (reduced) model: the one kernel behind
!> frirom.reduction.damping.modal_damping and frirom_solve's modal ratios.
!>
!> With the M-normalised modes Phi of K Phi = M Phi diag(omega^2), ascending,
!> C = M Phi_r diag(2 zeta_r omega_r) Phi_r^T M over the lowest size(zeta) modes r: mode r
!> gets the damping ratio zeta_r exactly (Phi^T C Phi = diag(2 zeta omega), zeros beyond),
!> and the modes stay uncoupled.
module frirom_damping
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_NONFINITE, FRIROM_ERR_LAPACK, FRIROM_ERR_MODEL, &
                             FRIROM_ERR_ALLOC, set_status
    use frirom_lapack, only: ilp, dsygv, dsyrk
    implicit none
    private
    public :: modal_damping

    !> An eigenvalue below -neg_tol max(|lambda|, 1) (over the damped modes) is negative,
    !> not round-off of a rigid-body mode.
    real(wp), parameter :: neg_tol = 1.0e-8_wp

contains

    !> Modal damping matrix C and the damped modes' circular frequencies. K and M are
    !> symmetric (their lower triangles are read); M must be positive definite and K
    !> positive semi-definite (a rigid-body mode, omega = 0, gets no damping).
    pure subroutine modal_damping(k, m, zeta, c, omega, info, errmsg)
        real(wp), intent(in) :: k(:, :)       !! (n, n) stiffness, N/m
        real(wp), intent(in) :: m(:, :)       !! (n, n) mass, kg
        real(wp), intent(in) :: zeta(:)       !! (nm) ratios >= 0 of the nm lowest modes
        real(wp), intent(out) :: c(:, :)      !! (n, n) damping, N s/m
        real(wp), intent(out) :: omega(:)     !! (nm) the damped modes' frequencies, rad/s
        integer(ip), intent(out) :: info      !! FRIROM_OK or the failure
        character(len=*), intent(inout), optional :: errmsg  !! what failed
        real(wp), allocatable :: a(:, :), b(:, :), w(:), work(:), mphi(:, :)
        real(wp) :: query(1), lmin
        integer(ip) :: n, nm, r, j, st
        integer(ilp) :: lst
        character(len=64) :: num
        info = FRIROM_OK
        n = size(k, 1)
        nm = size(zeta)
        c = 0.0_wp
        omega = 0.0_wp
        if (size(k, 2) /= n .or. size(m, 1) /= n .or. size(m, 2) /= n .or. &
            size(c, 1) /= n .or. size(c, 2) /= n .or. size(omega) /= nm) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'modal_damping: K, M and C must '// &
                            'be (n, n) and omega (size(zeta))')
            return
        end if
        if (nm < 1 .or. nm > n) then
            write (num, '(a, i0, a, i0)') 'got ', nm, ' ratios for n = ', n
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'modal_damping: the number of '// &
                            'ratios must lie in 1..n; '//trim(num))
            return
        end if
        if (.not. (all(ieee_is_finite(k)) .and. all(ieee_is_finite(m)))) then
            call set_status(info, FRIROM_ERR_NONFINITE, errmsg, 'modal_damping: K or M has '// &
                            'a NaN or Inf entry')
            return
        end if
        if (.not. all(ieee_is_finite(zeta)) .or. any(zeta < 0.0_wp)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'modal_damping: zeta must be '// &
                            'finite ratios >= 0')
            return
        end if
        allocate (a(n, n), b(n, n), w(n), stat=st)
        if (st /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'modal_damping: K, M copies')
            return
        end if
        a = k
        b = m
        call dsygv(1_ilp, 'V', 'L', int(n, ilp), a, int(n, ilp), b, int(n, ilp), w, query, &
                   -1_ilp, lst)
        allocate (work(max(1, int(query(1)))), stat=st)
        if (st /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'modal_damping: dsygv workspace')
            return
        end if
        call dsygv(1_ilp, 'V', 'L', int(n, ilp), a, int(n, ilp), b, int(n, ilp), w, work, &
                   int(size(work), ilp), lst)
        if (lst > n) then
            write (num, '(i0)') lst - n
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'modal_damping: M is not '// &
                            'positive definite (dsygv: its leading minor of order '// &
                            trim(num)//' is not)')
            return
        else if (lst /= 0) then
            write (num, '(i0)') lst
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'modal_damping: the eigen-'// &
                            'solve of (K, M) did not converge (dsygv info '//trim(num)//')')
            return
        end if
        lmin = minval(w(1:nm))
        if (lmin < -neg_tol*max(maxval(abs(w(1:nm))), 1.0_wp)) then
            write (num, '(es10.3)') lmin
            call set_status(info, FRIROM_ERR_MODEL, errmsg, 'modal_damping: K has a '// &
                            'negative eigenvalue '//trim(adjustl(num))//' (K must be '// &
                            'positive semi-definite)')
            return
        end if
        omega = sqrt(max(w(1:nm), 0.0_wp))
        ! C = (M Phi D^(1/2)) (M Phi D^(1/2))^T with D = diag(2 zeta omega) >= 0
        mphi = matmul(m, a(:, 1:nm))
        do r = 1, nm
            mphi(:, r) = mphi(:, r)*sqrt(2.0_wp*zeta(r)*omega(r))
        end do
        call dsyrk('L', 'N', int(n, ilp), int(nm, ilp), 1.0_wp, mphi, int(n, ilp), 0.0_wp, c, &
                   int(n, ilp))
        do j = 1, n
            c(j, j + 1:n) = c(j + 1:n, j)
        end do
    end subroutine modal_damping
end module frirom_damping
