!> Contact laws in the time domain: pure procedures, no state beyond what the caller passes.
!>
!> Each march takes the relative displacements of one element at the N samples of one
!> period and the slider position at the start, and returns the forces, the contact state
!> and the local derivatives at every sample, leaving the slider at its end-of-period
!> position. The AFT (frirom_aft) repeats the march until the cycle closes and turns the
!> local derivatives into the harmonic Jacobian.
!>
!> Sign convention: forces are those the element exerts against the relative displacement
!> (f_t = kt (u - w) in stick), so a stuck element is a spring of stiffness kt.
!>
!> Slider rules (Yang, Chu and Menq 1998 for the 1-D element with normal load variation;
!> the predictor-corrector used by Petrov and Ewins for the 2-D element):
!> - normal force f_n = max(n0 + kn v, 0); n0 < 0 is an initial gap g0 = -n0/kn;
!> - lift-off (f_n = 0): no tangential force, and the slider follows the contact point
!>   (w = u), so that the contact recloses unstretched where it touches down;
!> - otherwise the trial force kt (u - w) sticks when it lies within the friction limit
!>   mu f_n; beyond it the element slips, the force sits on the limit in the trial's
!>   direction and the slider moves to w = u - f_t/kt. A normal load that drops during
!>   stick therefore starts slip at the right sample: the test uses the current f_n.
module frirom_contact
    use frirom_kinds, only: wp, ip
    implicit none
    private

    public :: STATE_LIFTOFF, STATE_STICK, STATE_SLIP
    public :: jenkins_march, friction1d_march, friction2d_march, cubic_spring

    integer(ip), parameter :: STATE_LIFTOFF = 0  !! open contact, no force
    integer(ip), parameter :: STATE_STICK = 1    !! tangential spring, slider fixed
    integer(ip), parameter :: STATE_SLIP = 2     !! force on the friction limit, slider moves

contains

    !> Jenkins element (elastic Coulomb, constant normal load fn0) over one period.
    pure subroutine jenkins_march(u, kt, mu, fn0, w, ft, state)
        real(wp), intent(in) :: u(:)            !! (N) tangential relative displacement, m
        real(wp), intent(in) :: kt, mu, fn0     !! N/m, -, N (kt > 0, mu >= 0, fn0 >= 0)
        real(wp), intent(inout) :: w            !! slider position: start in, end out, m
        real(wp), intent(out) :: ft(:)          !! (N) tangential force, N
        integer(ip), intent(out) :: state(:)    !! (N) STATE_*
        integer(ip) :: k
        real(wp) :: t, lim
        lim = mu*fn0
        if (fn0 <= 0.0_wp) then
            ft = 0.0_wp
            state = STATE_LIFTOFF
            w = u(size(u))
            return
        end if
        do k = 1, size(u)
            t = kt*(u(k) - w)
            if (abs(t) <= lim) then
                ft(k) = t
                state(k) = STATE_STICK
            else
                ft(k) = sign(lim, t)
                w = u(k) - ft(k)/kt
                state(k) = STATE_SLIP
            end if
        end do
    end subroutine jenkins_march

    !> 1-D element with normal load variation over one period.
    !> dft_dv(k) = d f_t(k) / d v(k) at slip samples (s mu kn), 0 elsewhere: the only
    !> same-sample derivative that is not kt (stick) or kn (normal force in contact).
    pure subroutine friction1d_march(u, v, kt, kn, mu, n0, w, ft, fn, state, dft_dv)
        real(wp), intent(in) :: u(:)            !! (N) tangential relative displacement, m
        real(wp), intent(in) :: v(:)            !! (N) normal relative displacement, m (+ closes)
        real(wp), intent(in) :: kt, kn, mu, n0  !! N/m, N/m, -, N
        real(wp), intent(inout) :: w            !! slider position: start in, end out, m
        real(wp), intent(out) :: ft(:), fn(:)   !! (N) tangential and normal force, N
        integer(ip), intent(out) :: state(:)    !! (N) STATE_*
        real(wp), intent(out) :: dft_dv(:)      !! (N) see above, N/m
        integer(ip) :: k
        real(wp) :: t, lim
        do k = 1, size(u)
            fn(k) = n0 + kn*v(k)
            dft_dv(k) = 0.0_wp
            if (fn(k) <= 0.0_wp) then
                fn(k) = 0.0_wp
                ft(k) = 0.0_wp
                w = u(k)
                state(k) = STATE_LIFTOFF
                cycle
            end if
            t = kt*(u(k) - w)
            lim = mu*fn(k)
            if (abs(t) <= lim) then
                ft(k) = t
                state(k) = STATE_STICK
            else
                ft(k) = sign(lim, t)
                w = u(k) - ft(k)/kt
                state(k) = STATE_SLIP
                dft_dv(k) = sign(mu*kn, t)
            end if
        end do
    end subroutine friction1d_march

    !> 2-D tangential element (circular friction limit) with normal load variation over one
    !> period. At slip samples the local tangent of f_t with respect to the trial direction
    !> is returned: d f_t(k) = A_k (du_k - dw_{k-1}) + b_k dv_k, with
    !> A_k = (mu f_n / |t|) kt (I - n n^T), b_k = mu kn n, n = t/|t|; tangent(1:4, k) holds
    !> A_k column-major and tangent(5:6, k) holds b_k (zero at other samples).
    pure subroutine friction2d_march(u1, u2, v, kt, kn, mu, n0, w, f1, f2, fn, state, tangent)
        real(wp), intent(in) :: u1(:), u2(:)    !! (N) in-plane tangential relative displ., m
        real(wp), intent(in) :: v(:)            !! (N) normal relative displacement, m
        real(wp), intent(in) :: kt, kn, mu, n0  !! N/m, N/m, -, N
        real(wp), intent(inout) :: w(2)         !! slider position: start in, end out, m
        real(wp), intent(out) :: f1(:), f2(:), fn(:)  !! (N) forces, N
        integer(ip), intent(out) :: state(:)    !! (N) STATE_*
        real(wp), intent(out) :: tangent(:, :)  !! (6, N) slip tangents, see above
        integer(ip) :: k
        real(wp) :: t1, t2, tn, lim, n1, n2, r
        do k = 1, size(u1)
            fn(k) = n0 + kn*v(k)
            tangent(:, k) = 0.0_wp
            if (fn(k) <= 0.0_wp) then
                fn(k) = 0.0_wp
                f1(k) = 0.0_wp
                f2(k) = 0.0_wp
                w = [u1(k), u2(k)]
                state(k) = STATE_LIFTOFF
                cycle
            end if
            t1 = kt*(u1(k) - w(1))
            t2 = kt*(u2(k) - w(2))
            tn = hypot(t1, t2)
            lim = mu*fn(k)
            if (tn <= lim) then
                f1(k) = t1
                f2(k) = t2
                state(k) = STATE_STICK
            else
                n1 = t1/tn
                n2 = t2/tn
                f1(k) = lim*n1
                f2(k) = lim*n2
                w(1) = u1(k) - f1(k)/kt
                w(2) = u2(k) - f2(k)/kt
                state(k) = STATE_SLIP
                r = lim/tn*kt
                tangent(1, k) = r*(1.0_wp - n1*n1)
                tangent(2, k) = -r*n1*n2
                tangent(3, k) = -r*n1*n2
                tangent(4, k) = r*(1.0_wp - n2*n2)
                tangent(5, k) = mu*kn*n1
                tangent(6, k) = mu*kn*n2
            end if
        end do
    end subroutine friction2d_march

    !> Polynomial (cubic) spring f = k1 u + k3 u^3 and its derivative.
    elemental subroutine cubic_spring(u, k1, k3, f, dfdu)
        real(wp), intent(in) :: u, k1, k3  !! m, N/m, N/m^3
        real(wp), intent(out) :: f, dfdu   !! N, N/m
        f = u*(k1 + k3*u*u)
        dfdu = k1 + 3.0_wp*k3*u*u
    end subroutine cubic_spring
end module frirom_contact
