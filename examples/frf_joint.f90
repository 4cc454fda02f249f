!> The bundled joint case (cases/joint/joint.toml: a lumped blade with an underplatform
!> friction damper) solved through frirom_solve, the model written as arrays. Prints
!> "omega_rad_s amp(tip:x) amp(platform:x) amp(platform:y)" per point (m), then
!> "complete T|F npts".
program frf_joint
    use frirom_kinds, only: wp, ip
    use frirom_solve, only: frf_settings, frf_result, frf_solve, FRF_CONDENSED
    implicit none
    real(wp), parameter :: pi = acos(-1.0_wp)
    ! K (N/m): every entry of the symmetric 5 x 5 matrix (cases/joint/K.mtx)
    integer(ip), parameter :: kr(11) = [1, 2, 3, 1, 3, 4, 3, 4, 5, 4, 5]
    integer(ip), parameter :: kc(11) = [1, 2, 1, 3, 3, 3, 4, 4, 4, 5, 5]
    real(wp), parameter :: kv(11) = [5.5e6_wp, 8.0e6_wp, -1.5e6_wp, -1.5e6_wp, 2.5e6_wp, &
                                     -1.0e6_wp, -1.0e6_wp, 1.6e6_wp, -6.0e5_wp, -6.0e5_wp, &
                                     6.0e5_wp]
    ! M (kg), diagonal; DoFs: platform:x, platform:y, blade_low:x, blade_mid:x, tip:x
    integer(ip), parameter :: md(5) = [1, 2, 3, 4, 5]
    real(wp), parameter :: mv(5) = [0.08_wp, 0.08_wp, 0.03_wp, 0.03_wp, 0.02_wp]
    ! one Jenkins element (law 1: kt N/m, mu, fn0 N) on the platform's 30 deg face:
    ! u = cos 30 x + sin 30 y of the platform, against the ground
    integer(ip), parameter :: ginfo(3, 1) = reshape([1, 1, 1], [3, 1])
    integer(ip), parameter :: gr(2) = [1, 1], gc(2) = [1, 2]
    real(wp), parameter :: gv(2) = [0.8660254037844386_wp, 0.5_wp]
    real(wp), parameter :: params(3) = [1.0e7_wp, 0.5_wp, 100.0_wp]
    integer(ip), parameter :: outdofs(3) = [5, 1, 2]
    integer(ip), allocatable :: none(:)
    real(wp), allocatable :: nonev(:)
    type(frf_settings) :: s
    type(frf_result) :: res
    real(wp) :: fe(5, 11), zeta(5)
    integer(ip) :: k

    s%harmonics = 5
    s%samples = 64
    s%formulation = FRF_CONDENSED
    s%ds = 0.02_wp
    s%ds_max = 0.1_wp
    s%max_points = 1000
    zeta = 0.003_wp                 ! modal damping of every mode
    fe = 0.0_wp
    fe(5, 2) = 2.0_wp               ! 2 N cos(omega t) at the tip (harmonic 1, cosine)
    allocate (none(0), nonev(0))    ! no damping matrix besides the modal one
    call frf_solve(5, kr, kc, kv, md, md, mv, none, none, nonev, 0.0_wp, 0.0_wp, zeta, &
                   ginfo, gr, gc, gv, params, fe, 2*pi*400.0_wp, 2*pi*520.0_wp, outdofs, s, res)
    if (res%info /= 0 .and. res%npts == 0) then
        print '(a)', trim(res%message)
        error stop 1
    end if
    do k = 1, res%npts
        print '(4es24.16)', res%omega(k), res%amp(:, k)
    end do
    print '(a,l2,i6)', 'complete', res%complete, res%npts
    if (.not. res%complete) print '(a)', trim(res%message)
end program frf_joint
