!> frirom_fourier against direct trigonometric sums: synthesis, analysis, the
!> multiplication matrix built from trig sums, run-length sums, and size checks.
program test_fourier
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_fourier
    implicit none
    integer(ip), parameter :: nh = 4, ns = 32, nc = 2*nh + 1
    type(fourier_plan) :: plan
    integer(ip) :: info, k, i, j, m, col
    real(wp) :: xh(nc, 3), yh(nc), c(ns), tau, direct(ns), jac(nc, nc), ref(nc, nc)
    real(wp) :: cm(0:2*nh), sm(0:2*nh), cm2(0:2*nh), sm2(0:2*nh), err
    character(len=200) :: msg

    call fourier_plan_create(plan, 3_ip, 6_ip, 4_ip, 1_ip, 1_ip, .false., info, msg)
    if (info /= FRIROM_ERR_SAMPLES) error stop 'N < 2H+1 must be rejected'
    if (index(msg, '2H+1') == 0) error stop 'the message must say N >= 2H+1'
    ! buffers of 2^30 samples x 2^20 signals (8 PiB): a status code, not a crash
    call fourier_plan_create(plan, 1_ip, 2_ip**30, 2_ip**20, 1_ip, 1_ip, .false., info, msg)
    if (info /= FRIROM_ERR_ALLOC) error stop 'a failed fftw_alloc must give FRIROM_ERR_ALLOC'
    if (index(msg, 'fftw_alloc') == 0) error stop 'the message must name fftw_alloc'

    call fourier_plan_create(plan, nh, ns, 3_ip, 2_ip, 2_ip, .false., info, msg)
    if (info /= FRIROM_OK) error stop 'plan creation failed'
    call random_number(xh)
    call clear_input(plan, 2_ip)
    do col = 1, 3
        call load_harmonics(plan, 2_ip, col, xh(:, col))
    end do
    call exec_c2r(plan, 2_ip)
    err = 0.0_wp
    do col = 1, 3
        do k = 1, ns
            tau = 2.0_wp*acos(-1.0_wp)*real(k - 1, wp)/real(ns, wp)
            direct(k) = xh(1, col)
            do i = 1, nh
                direct(k) = direct(k) + xh(2*i, col)*cos(i*tau) + xh(2*i + 1, col)*sin(i*tau)
            end do
        end do
        err = max(err, maxval(abs(plan%rin(col, :, 2) - direct)))
        plan%rout(col, :, 1) = plan%rin(col, :, 2)
    end do
    if (err > 1.0e-13_wp) error stop 'synthesis differs from the direct sum'
    call exec_r2c(plan, 1_ip)
    do col = 1, 3
        call harmonics_of(plan, 1_ip, col, yh)
        if (maxval(abs(yh - xh(:, col))) > 1.0e-13_wp) error stop 'analysis does not invert synthesis'
    end do

    ! the AFT's table transforms (H <= DIRECT_MAX_HARM) against the FFTW pair above, on
    ! the first 2 of the 4 batch signals (a short batch): tolerance 1e-14 of the O(1) data
    ! (both sums are exact to a few ulps of the 2H+1 or N terms)
    if (.not. plan%direct) error stop 'H = 4 must use the table transforms'
    plan%coef = 0.0_wp
    plan%rin(:, :, 1) = 7.0_wp   ! rows beyond m must be left alone
    do col = 1, 2
        plan%coef(col, :) = xh(:, col)
    end do
    call synth_direct(plan, 1_ip, 2_ip)
    if (maxval(abs(plan%rin(1:2, :, 1) - plan%rin(1:2, :, 2))) > 1.0e-14_wp) &
        error stop 'synth_direct differs from the FFT synthesis'
    if (any(plan%rin(3:, :, 1) /= 7.0_wp)) error stop 'synth_direct wrote beyond m'
    plan%rout(1:2, :, 2) = plan%rin(1:2, :, 1)**2   ! harmonics up to 2H: aliasing-free at N
    call analyse_direct(plan, 2_ip, 2_ip)
    call exec_r2c(plan, 2_ip)
    do col = 1, 2
        call harmonics_of(plan, 2_ip, col, yh)
        if (maxval(abs(yh - plan%coef(col, :))) > 1.0e-14_wp) &
            error stop 'analyse_direct differs from the FFT analysis'
    end do

    ! multiplication matrix of a random series: toeplitz_add vs sum_k P(:,k) c_k E(k,:)
    call random_number(c)
    plan%rout(1, :, 2) = c
    call exec_r2c(plan, 2_ip)
    call trig_sums(plan, 2_ip, 1_ip, cm, sm)
    jac = 0.0_wp
    call toeplitz_add(nh, ns, cm, sm, jac, 0_ip, 0_ip)
    do i = 1, nc
        do j = 1, nc
            ref(i, j) = plan%weight(i)*sum(plan%basis(:, i)*c*plan%basis(:, j))
        end do
    end do
    if (maxval(abs(jac - ref)) > 1.0e-13_wp) error stop 'toeplitz_add differs from P diag(c) E'

    ! run-length sums of a piecewise-constant series equal the FFT-based ones
    c = 0.0_wp
    c(3:10) = 2.5_wp
    c(20:32) = -1.0_wp
    plan%rout(1, :, 2) = c
    call exec_r2c(plan, 2_ip)
    call trig_sums(plan, 2_ip, 1_ip, cm, sm)
    call run_trig_sums(plan, c, cm2, sm2)
    if (maxval(abs(cm - cm2)) + maxval(abs(sm - sm2)) > 1.0e-12_wp) &
        error stop 'run-length trig sums differ from the FFT'
    do m = 0, 2*nh
        if (abs(cm2(m) - sum(c*cos(m*2.0_wp*acos(-1.0_wp)*[(real(k, wp), k=0, ns - 1)]/ns))) &
            > 1.0e-12_wp) error stop 'run-length cosine sum wrong'
    end do
    call fourier_plan_destroy(plan)
    call fourier_plan_destroy(plan)   ! twice is safe
    print '(a)', 'test_fourier: ok'
end program test_fourier
