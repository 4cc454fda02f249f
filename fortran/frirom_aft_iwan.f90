!> Iwan elements: parallel Jenkins sliders under one tangential relative displacement.
!>
!> An Iwan element is a set of Jenkins sliders (stiffness k_s, slip force fs_s) that share
!> the displacement u; its force is the sum of theirs. The AFT therefore marches, transforms
!> and differentiates each slider with the Jenkins law (frirom_contact jenkins_march and
!> the analytical Jenkins Jacobian, consistent with the time marching) and sums: forces and
!> Jacobians of an Iwan element are the sums over its sliders, exactly. The slider state
!> (one position per slider) is carried along the period and between continuation points
!> like the Jenkins slider.
!>
!> - `iwan` (discrete): up to IWAN_MAX sliders given by (k_s, fs_s); k_s = 0 leaves slider s
!>   unused.
!> - `iwan4` (Segalman 2005, four parameters fs = F_S, kt = K_T, chi, beta): the density of
!>   break displacements rho(phi) = R phi^chi on (0, phi_max) plus S delta(phi - phi_max),
!>   phi_max = F_S (1 + beta) / (K_T (beta + (chi+1)/(chi+2))),
!>   R = F_S (chi+1) / (phi_max^(chi+2) (beta + (chi+1)/(chi+2))),
!>   S = F_S beta / (phi_max (beta + (chi+1)/(chi+2))) (so K_T = int rho, F_S = int rho phi).
!>   Discretisation: IWAN4_BINS bins of (0, phi_max) with geometric edges phi_i =
!>   phi_max 10^(-3 (B - i)/(B - 1)), i = 1..B, phi_0 = 0; bin i becomes one slider with
!>   the bin's zeroth and first moments, k_i = int rho, fs_i = int rho phi (break
!>   displacement at the bin's centroid), plus one slider (S, S phi_max) for the Dirac part.
!>   Both moments are exact, so the stiffness K_T, the macroslip force F_S and the
!>   dissipation at amplitudes above phi_max are exact; below phi_max the dissipation per
!>   cycle differs from the closed form 4 R A^(chi+3) / ((chi+2)(chi+3)) by the quadrature
!>   error of the bin holding A (measured in tests/test_iwan.py, chi in [-0.8, 0]: < 3 % for
!>   A in [1e-2, 1] phi_max, < 7 % at 3e-3 phi_max, < 0.2 % above 2 phi_max; below the
!>   first edge 1e-3 phi_max the element is a linear spring, dissipating nothing).
submodule (frirom_aft) frirom_aft_iwan
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_NOCLOSE
    implicit none

    integer(ip), parameter :: CHUNK = 16   !! Iwan elements expanded at a time

contains

    module procedure iwan_sliders
        integer(ip) :: i, nb
        real(wp) :: fsm, ktm, chi, beta, den, phimax, r, s, a, b
        k = 0.0_wp
        fs = 0.0_wp
        if (law == LAW_IWAN) then
            k(1:IWAN_MAX) = max(p(1::2), 0.0_wp)
            fs(1:IWAN_MAX) = max(p(2::2), 0.0_wp)
            return
        end if
        fsm = p(1)
        ktm = p(2)
        chi = p(3)
        beta = p(4)
        nb = IWAN4_BINS
        den = beta + (chi + 1.0_wp)/(chi + 2.0_wp)
        phimax = fsm*(1.0_wp + beta)/(ktm*den)
        r = fsm*(chi + 1.0_wp)/(phimax**(chi + 2.0_wp)*den)
        s = fsm*beta/(phimax*den)
        a = 0.0_wp
        do i = 1, nb
            b = phimax*10.0_wp**(-3.0_wp*real(nb - i, wp)/real(nb - 1, wp))
            if (i == nb) b = phimax
            k(i) = r*(b**(chi + 1.0_wp) - a**(chi + 1.0_wp))/(chi + 1.0_wp)
            fs(i) = r*(b**(chi + 2.0_wp) - a**(chi + 2.0_wp))/(chi + 2.0_wp)
            a = b
        end do
        k(nb + 1) = s
        fs(nb + 1) = s*phimax
    end procedure iwan_sliders

    module procedure iwan_forces
        integer(ip) :: ne, nc, ns, e0, mc, ie, n, q
        real(wp) :: ktot
        integer(ip), allocatable :: owner(:), slot(:), per(:)
        real(wp), allocatable :: xs(:, :, :), ps(:, :), ws(:, :), fsub(:, :, :), &
                                 jsub(:, :, :), st(:, :), wout(:, :)
        logical :: want_jac

        info = FRIROM_OK
        ne = size(x, 3)
        nc = size(x, 1)
        ns = NSLIDER_OF(law)
        want_jac = present(jac)
        allocate (owner(CHUNK*ns), slot(CHUNK*ns), per(CHUNK*ns))
        allocate (xs(nc, 1, CHUNK*ns), ps(3, CHUNK*ns), ws(1, CHUNK*ns), &
                  fsub(nc, 1, CHUNK*ns), st(3, CHUNK*ns), wout(1, CHUNK*ns))
        if (want_jac) allocate (jsub(nc, nc, CHUNK*ns))
        do e0 = 1, ne, CHUNK
            mc = min(CHUNK, ne - e0 + 1)
            if (present(slider)) slider(1:ns, e0:e0 + mc - 1) = w0(1:ns, e0:e0 + mc - 1)
            call gather(law, x, params, w0, e0, mc, n, owner, slot, xs, ps, ws)
            if (want_jac) then
                call aft_forces(plan, LAW_JENKINS, xs(:, :, 1:n), ps(:, 1:n), ws(:, 1:n), &
                                fsub(:, :, 1:n), info, errmsg, jac=jsub(:, :, 1:n), &
                                periods=per(1:n), states=st(:, 1:n), tol=tol, &
                                max_periods=max_periods, slider=wout(:, 1:n))
            else
                call aft_forces(plan, LAW_JENKINS, xs(:, :, 1:n), ps(:, 1:n), ws(:, 1:n), &
                                fsub(:, :, 1:n), info, errmsg, periods=per(1:n), &
                                states=st(:, 1:n), tol=tol, max_periods=max_periods, &
                                slider=wout(:, 1:n))
            end if
            if (info /= FRIROM_OK .and. info /= FRIROM_ERR_NOCLOSE) return
            f(:, :, e0:e0 + mc - 1) = 0.0_wp
            if (want_jac) jac(:, :, e0:e0 + mc - 1) = 0.0_wp
            if (present(periods)) periods(e0:e0 + mc - 1) = 0
            if (present(states)) states(:, e0:e0 + mc - 1) = 0.0_wp
            do q = 1, n
                ie = owner(q)
                f(:, 1, ie) = f(:, 1, ie) + fsub(:, 1, q)
                if (want_jac) jac(:, :, ie) = jac(:, :, ie) + jsub(:, :, q)
                if (present(periods)) periods(ie) = max(periods(ie), per(q))
                ! state fractions weighted by the sliders' stiffness
                if (present(states)) states(:, ie) = states(:, ie) + ps(1, q)*st(:, q)
                if (present(slider)) slider(slot(q), ie) = wout(1, q)
            end do
            if (present(states)) then
                do ie = e0, e0 + mc - 1
                    ktot = sum(states(:, ie))
                    if (ktot > 0.0_wp) states(:, ie) = states(:, ie)/ktot
                end do
            end if
            if (info == FRIROM_ERR_NOCLOSE) return
        end do
    end procedure iwan_forces

    module procedure iwan_histories
        integer(ip) :: ne, nc, ns, nsamp, e0, mc, ie, n, q
        integer(ip), allocatable :: owner(:), slot(:)
        real(wp), allocatable :: xs(:, :, :), ps(:, :), ws(:, :), xts(:, :, :), fts(:, :, :)

        info = FRIROM_OK
        ne = size(x, 3)
        nc = size(x, 1)
        ns = NSLIDER_OF(law)
        nsamp = size(xt, 1)
        allocate (owner(CHUNK*ns), slot(CHUNK*ns), xs(nc, 1, CHUNK*ns), ps(3, CHUNK*ns), &
                  ws(1, CHUNK*ns), xts(nsamp, 1, CHUNK*ns), fts(nsamp, 1, CHUNK*ns))
        do e0 = 1, ne, CHUNK
            mc = min(CHUNK, ne - e0 + 1)
            call gather(law, x, params, w0, e0, mc, n, owner, slot, xs, ps, ws)
            call aft_histories(plan, LAW_JENKINS, xs(:, :, 1:n), ps(:, 1:n), ws(:, 1:n), &
                               xts(:, :, 1:n), fts(:, :, 1:n), info, errmsg, tol=tol, &
                               max_periods=max_periods, index_base=index_base)
            if (info /= FRIROM_OK) return
            ft(:, :, e0:e0 + mc - 1) = 0.0_wp
            do q = 1, n
                ie = owner(q)
                xt(:, 1, ie) = xts(:, 1, q)
                ft(:, 1, ie) = ft(:, 1, ie) + fts(:, 1, q)
            end do
        end do
    end procedure iwan_histories

    !> The sliders with stiffness > 0 of elements e0 .. e0 + mc - 1 as n Jenkins elements:
    !> their element (owner) and slider (slot), displacement xs, parameters ps = [k_s, 1,
    !> fs_s] (mu 1, the slip force as the normal load) and start positions ws.
    subroutine gather(law, x, params, w0, e0, mc, n, owner, slot, xs, ps, ws)
        integer(ip), intent(in) :: law, e0, mc
        real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :)
        integer(ip), intent(out) :: n
        integer(ip), intent(inout) :: owner(:), slot(:)
        real(wp), intent(inout) :: xs(:, :, :), ps(:, :), ws(:, :)
        real(wp) :: ks(NSLIDER_OF(law)), fss(NSLIDER_OF(law))
        integer(ip) :: ie, s
        n = 0
        do ie = e0, e0 + mc - 1
            call iwan_sliders(law, params(:, ie), ks, fss)
            do s = 1, size(ks)
                if (ks(s) <= 0.0_wp) cycle
                n = n + 1
                owner(n) = ie
                slot(n) = s
                xs(:, 1, n) = x(:, 1, ie)
                ps(:, n) = [ks(s), 1.0_wp, fss(s)]
                ws(1, n) = w0(s, ie)
            end do
        end do
    end subroutine gather
end submodule frirom_aft_iwan
