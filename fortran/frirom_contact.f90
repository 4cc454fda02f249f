!> Contact laws in the time domain: pure procedures, no state beyond what the caller passes.
!>
!> Each march takes the relative displacements of m elements at the N samples of one
!> period, laid out (m, N), and their slider positions at the start, and returns the
!> forces, the contact state and the local derivatives at every sample, leaving the
!> sliders at their end-of-period positions. Elements advance together, sample after
!> sample, with branch-free updates: the slider recurrence of one element is a serial
!> chain, but m independent chains side by side vectorise and hide its latency.
!> The AFT (frirom_aft) repeats the march until the cycles close and turns the local
!> derivatives into the harmonic Jacobian.
!>
!> Sign convention: forces are those the element exerts against the relative displacement
!> (f_t = kt (u - w) in stick), so a stuck element is a spring of stiffness kt.
!>
!> Slider rules (Yang, Chu and Menq 1998 for the 1-D element with normal load variation;
!> the predictor-corrector used by Petrov and Ewins for the 2-D element):
!> - normal force f_n = max(n0 + kn v, 0); n0 < 0 is an initial gap g0 = -n0/kn;
!> - lift-off (f_n = 0): no tangential force, and the slider follows the contact point
!>   (w = u), so that the contact recloses unstretched where it touches down, at the
!>   re-contact instant between two samples: the marches take, in place of u, the
!>   positions recontact_follow gives (u, except at the last open sample before the
!>   contact recloses, where it is u at the instant the linearly interpolated normal force
!>   crosses zero). Anchoring the slider at that open sample instead would be off by
!>   O(1/N) for the whole stick that follows: a first-order AFT. Done before the march,
!>   once for all its periods, the march itself stays as lean as without lift-off;
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
    public :: recontact_follow

    integer(ip), parameter :: STATE_LIFTOFF = 0  !! open contact, no force
    integer(ip), parameter :: STATE_STICK = 1    !! tangential spring, slider fixed
    integer(ip), parameter :: STATE_SLIP = 2     !! force on the friction limit, slider moves

contains

    !> Jenkins elements (elastic Coulomb, constant normal load fn0) over one period.
    pure subroutine jenkins_march(u, kt, mu, fn0, w, ft, state)
        real(wp), intent(in) :: u(:, :)          !! (m, N) tangential relative displacement, m
        real(wp), intent(in) :: kt(:), mu(:), fn0(:)  !! (m) N/m, -, N
        real(wp), intent(inout) :: w(:)          !! (m) slider position: start in, end out, m
        real(wp), intent(out) :: ft(:, :)        !! (m, N) tangential force, N
        integer(ip), intent(out) :: state(:, :)  !! (m, N) STATE_*
        integer(ip) :: j, k
        real(wp) :: t, lim, f, fs, ws
        logical :: slip
        ! An open contact (fn0 = 0) has lim = 0: the slip update then gives f = 0 and
        ! w = u, the lift-off rules, so one branch-free update serves all states.
        do k = 1, size(u, 2)
            do j = 1, size(u, 1)
                lim = mu(j)*merge(fn0(j), 0.0_wp, fn0(j) > 0.0_wp)
                t = kt(j)*(u(j, k) - w(j))
                slip = abs(t) > lim
                fs = sign(lim, t)
                ws = u(j, k) - fs/kt(j)
                f = merge(fs, t, slip)
                w(j) = merge(ws, w(j), slip)
                ft(j, k) = f
                state(j, k) = merge(STATE_SLIP, STATE_STICK, slip)
                state(j, k) = merge(STATE_LIFTOFF, state(j, k), fn0(j) <= 0.0_wp)
            end do
        end do
    end subroutine jenkins_march

    !> 1-D elements with normal load variation over one period.
    !> dft_dv(j, k) = d f_t / d v at the same sample: s mu kn at slip samples, 0 elsewhere
    !> (the only same-sample derivative besides kt in stick and kn in contact).
    pure subroutine friction1d_march(u, v, kt, kn, mu, n0, w, ft, fn, state, dft_dv)
        real(wp), intent(in), contiguous :: u(:, :)   !! (m, N) tangential relative displ.
                                                      !! (recontact_follow's uf), m
        real(wp), intent(in), contiguous :: v(:, :)   !! (m, N) normal relative displacement,
                                                      !! m (positive closes)
        real(wp), intent(in), contiguous :: kt(:), kn(:), mu(:), n0(:)  !! (m) N/m, N/m, -, N
        real(wp), intent(inout), contiguous :: w(:)   !! (m) slider: start in, end out, m
        real(wp), intent(out), contiguous :: ft(:, :), fn(:, :)  !! (m, N) forces, N
        integer(ip), intent(out), contiguous :: state(:, :)     !! (m, N) STATE_*
        real(wp), intent(out), contiguous :: dft_dv(:, :)       !! (m, N) see above, N/m
        integer(ip) :: j, k
        real(wp) :: t, lim, f, nf, closed, fs, ws, ds
        logical :: slip
        ! Contiguous arguments: the loop over elements vectorises at full width (AVX-512: 8
        ! elements a vector) instead of the 2 lanes a possibly strided section allows.
        ! Open contact: lim = 0, so the slip update gives f = 0 and w = u (lift-off rules)
        ! and one branch-free update serves all states; `closed` zeroes d ft/dv there.
        do k = 1, size(u, 2)
            do j = 1, size(u, 1)
                nf = n0(j) + kn(j)*v(j, k)
                closed = merge(1.0_wp, 0.0_wp, nf > 0.0_wp)
                nf = closed*nf   ! max(nf, 0) without the branch gfortran's MAX carries
                lim = mu(j)*nf
                t = kt(j)*(u(j, k) - w(j))
                slip = abs(t) > lim
                ! operands computed unconditionally so the selects are blends, not branches
                fs = sign(lim, t)
                ws = u(j, k) - fs/kt(j)
                ds = sign(mu(j)*kn(j), t)
                f = merge(fs, t, slip)
                w(j) = merge(ws, w(j), slip)
                ft(j, k) = f
                fn(j, k) = nf
                dft_dv(j, k) = closed*merge(ds, 0.0_wp, slip)
                state(j, k) = merge(STATE_SLIP, STATE_STICK, slip)
                state(j, k) = merge(STATE_LIFTOFF, state(j, k), closed == 0.0_wp)
            end do
        end do
    end subroutine friction1d_march

    !> 2-D tangential elements (circular friction limit) with normal load variation over one
    !> period. At slip samples the local tangent of f_t is returned:
    !> d f_t(k) = A_k (du_k - dw_{k-1}) + b_k dv_k, with A_k = (mu f_n / |t|) kt (I - n n^T),
    !> b_k = mu kn n, n = t/|t|; tangent(j, 1:4, k) holds A_k column-major and
    !> tangent(j, 5:6, k) holds b_k (zero at other samples).
    pure subroutine friction2d_march(u1, u2, v, kt, kn, mu, n0, w, f1, f2, fn, state, tangent)
        real(wp), intent(in) :: u1(:, :), u2(:, :)  !! (m, N) in-plane tangential displ.
                                                    !! (recontact_follow's uf), m
        real(wp), intent(in) :: v(:, :)          !! (m, N) normal relative displacement, m
        real(wp), intent(in) :: kt(:), kn(:), mu(:), n0(:)  !! (m) N/m, N/m, -, N
        real(wp), intent(inout) :: w(:, :)       !! (m, 2) slider position: start in, end out
        real(wp), intent(out) :: f1(:, :), f2(:, :), fn(:, :)  !! (m, N) forces, N
        integer(ip), intent(out) :: state(:, :)  !! (m, N) STATE_*
        real(wp), intent(out) :: tangent(:, :, :)  !! (m, 6, N) slip tangents, see above
        integer(ip) :: j, k
        real(wp) :: t1, t2, tn, lim, n1, n2, r, nf, g1, g2
        logical :: slip, open
        do k = 1, size(u1, 2)
            do j = 1, size(u1, 1)
                nf = n0(j) + kn(j)*v(j, k)
                open = nf <= 0.0_wp
                nf = max(nf, 0.0_wp)
                lim = mu(j)*nf
                t1 = kt(j)*(u1(j, k) - w(j, 1))
                t2 = kt(j)*(u2(j, k) - w(j, 2))
                tn = hypot(t1, t2)
                slip = tn > lim .and. .not. open
                n1 = t1/max(tn, tiny(1.0_wp))
                n2 = t2/max(tn, tiny(1.0_wp))
                g1 = merge(lim*n1, t1, slip)
                g2 = merge(lim*n2, t2, slip)
                w(j, 1) = merge(u1(j, k), merge(u1(j, k) - g1/kt(j), w(j, 1), slip), open)
                w(j, 2) = merge(u2(j, k), merge(u2(j, k) - g2/kt(j), w(j, 2), slip), open)
                f1(j, k) = merge(0.0_wp, g1, open)
                f2(j, k) = merge(0.0_wp, g2, open)
                fn(j, k) = nf
                state(j, k) = merge(STATE_LIFTOFF, merge(STATE_SLIP, STATE_STICK, slip), open)
                r = merge(lim/max(tn, tiny(1.0_wp))*kt(j), 0.0_wp, slip)
                tangent(j, 1, k) = r*(1.0_wp - n1*n1)
                tangent(j, 2, k) = -r*n1*n2
                tangent(j, 3, k) = -r*n1*n2
                tangent(j, 4, k) = r*(1.0_wp - n2*n2)
                tangent(j, 5, k) = merge(mu(j)*kn(j)*n1, 0.0_wp, slip)
                tangent(j, 6, k) = merge(mu(j)*kn(j)*n2, 0.0_wp, slip)
            end do
        end do
    end subroutine friction2d_march

    !> Positions the slider of an element with normal load variation follows: u, except at
    !> an open sample k-1 followed by a closed sample k, where it is the re-contact point
    !> u_{k-1} + theta (u_k - u_{k-1}), theta = g_{k-1}/(g_{k-1} - g_k), g = n0 + kn v
    !> (sample 0 is sample N: the motion is periodic). The marches take uf in place of u:
    !> the forces at open samples are zero whatever u, and the slider leaves the last open
    !> sample where the contact closes.
    pure subroutine recontact_follow(u, v, kn, n0, uf)
        real(wp), intent(in) :: u(:, :)          !! (m, N) a tangential relative displ., m
        real(wp), intent(in) :: v(:, :)          !! (m, N) normal relative displacement, m
        real(wp), intent(in) :: kn(:), n0(:)     !! (m) N/m, N
        real(wp), intent(out) :: uf(:, :)        !! (m, N) positions for the march, m
        integer(ip) :: j, k, k1
        real(wp) :: g, g1, theta
        logical :: reclose
        do k = 1, size(u, 2)
            k1 = k + 1
            if (k == size(u, 2)) k1 = 1
            do j = 1, size(u, 1)
                g = n0(j) + kn(j)*v(j, k)
                g1 = n0(j) + kn(j)*v(j, k1)
                reclose = g <= 0.0_wp .and. g1 > 0.0_wp
                theta = g/merge(g - g1, -1.0_wp, reclose)
                uf(j, k) = merge(u(j, k) + theta*(u(j, k1) - u(j, k)), u(j, k), reclose)
            end do
        end do
    end subroutine recontact_follow

    !> Polynomial (cubic) spring f = k1 u + k3 u^3 and its derivative.
    elemental subroutine cubic_spring(u, k1, k3, f, dfdu)
        real(wp), intent(in) :: u, k1, k3  !! m, N/m, N/m^3
        real(wp), intent(out) :: f, dfdu   !! N, N/m
        f = u*(k1 + k3*u*u)
        dfdu = k1 + 3.0_wp*k3*u*u
    end subroutine cubic_spring
end module frirom_contact
