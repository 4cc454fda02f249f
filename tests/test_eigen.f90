!> frirom_eigen against closed forms: a fixed-fixed chain of n masses m and n+1 springs k
!! has lambda_j = (4 k / m) sin^2(j pi / (2 (n+1))) and modes sin(i j pi / (n+1)).
!! Checked: eigenvalues (1e-10 relative: ARPACK converges to machine precision on this
!! well separated spectrum), M-orthonormality, shift inside the spectrum (indefinite LDL^T),
!! static solves with several right-hand sides, and bad input returning a status.
program test_eigen
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done
    use frirom_status, only: FRIROM_OK
    use frirom_eigen, only: eigen_work, eigen_factor, eigen_solve, eigen_modes, eigen_destroy
    implicit none
    integer(ip), parameter :: n = 3000, nev = 12
    real(wp), parameter :: k = 2.0e6_wp, m = 0.5_wp, pi = acos(-1.0_wp)
    type(eigen_work) :: work
    integer(ip), allocatable :: kr(:), kc(:), mr(:), mc(:), mptr(:), mind(:)
    real(wp), allocatable :: kv(:), mv(:), mval(:), lam(:), phi(:, :), exact(:), b(:, :), x(:, :)
    integer(ip) :: i, j, info, nk, first
    character(len=512) :: msg
    real(wp) :: err, sigma

    ! K upper triangle: diagonal 2k, superdiagonal -k. M = m I (also as CSR).
    nk = 2*n - 1
    allocate (kr(nk), kc(nk), kv(nk))
    kr(1:n) = [(i, i=1, n)]
    kc(1:n) = kr(1:n)
    kv(1:n) = 2.0_wp*k
    kr(n + 1:nk) = [(i, i=1, n - 1)]
    kc(n + 1:nk) = [(i + 1, i=1, n - 1)]
    kv(n + 1:nk) = -k
    mr = [(i, i=1, n)]
    mc = mr
    mv = [(m, i=1, n)]
    mptr = [(i, i=1, n + 1)]
    mind = mr
    mval = mv
    allocate (lam(nev), phi(n, nev), exact(n))
    exact = [((4.0_wp*k/m)*sin(j*pi/(2.0_wp*(n + 1)))**2, j=1, n)]

    ! Lowest modes, shift 0 (positive definite factor).
    call eigen_factor(work, n, kr, kc, kv, mr, mc, mv, 0.0_wp, info, msg)
    call check(info == FRIROM_OK, 'factor sigma=0: '//trim(msg))
    call eigen_modes(work, mptr, mind, mval, nev, lam, phi, info, msg)
    call check(info == FRIROM_OK, 'modes sigma=0: '//trim(msg))
    err = maxval(abs(lam - exact(1:nev))/exact(1:nev))
    print '(a,es10.3)', 'sigma = 0: max relative eigenvalue error ', err
    call check(err < 1.0e-10_wp, 'eigenvalues at sigma = 0')
    err = maxval(abs(m*matmul(transpose(phi), phi) - eye(nev)))
    print '(a,es10.3)', 'M-orthonormality error ', err
    call check(err < 1.0e-10_wp, 'M-orthonormality')

    ! Static solves with the same factor: K x = b for 3 right-hand sides.
    allocate (b(n, 3))
    call random_number(b)
    x = b
    call eigen_solve(work, x, info, msg)
    call check(info == FRIROM_OK, 'solve: '//trim(msg))
    err = maxval(abs(kmul(x) - b))/maxval(abs(b))
    print '(a,es10.3)', 'static solve residual ', err
    call check(err < 1.0e-8_wp, 'static solve residual')

    ! Shift inside the spectrum: the nev eigenvalues nearest sigma (indefinite LDL^T).
    first = 200
    sigma = 0.5_wp*(exact(first + nev/2) + exact(first + nev/2 + 1))
    call eigen_factor(work, n, kr, kc, kv, mr, mc, mv, sigma, info, msg)
    call check(info == FRIROM_OK, 'factor interior shift: '//trim(msg))
    call eigen_modes(work, mptr, mind, mval, nev, lam, phi, info, msg)
    call check(info == FRIROM_OK, 'modes interior shift: '//trim(msg))
    err = maxval(abs(lam - exact(first + 1:first + nev))/exact(first + 1:first + nev))
    print '(a,es10.3)', 'interior shift: max relative eigenvalue error ', err
    call check(err < 1.0e-10_wp, 'eigenvalues at an interior shift')

    ! Bad input gives a status, never a crash.
    kr(1) = n + 5
    call eigen_factor(work, n, kr, kc, kv, mr, mc, mv, 0.0_wp, info, msg)
    call check(info /= FRIROM_OK .and. index(msg, 'outside') > 0, 'bad index detected')
    kr(1) = 1
    call eigen_factor(work, n, kr, kc, kv, mr, mc, mv, 0.0_wp, info, msg)
    call eigen_modes(work, mptr, mind, mval, n, lam, phi, info, msg)
    call check(info /= FRIROM_OK, 'nev >= n rejected')
    call eigen_destroy(work)
    call check_done('test_eigen')

contains

    function kmul(v) result(w)
        real(wp), intent(in) :: v(:, :)
        real(wp) :: w(size(v, 1), size(v, 2))
        integer(ip) :: r
        w = 2.0_wp*k*v
        do r = 1, n - 1
            w(r, :) = w(r, :) - k*v(r + 1, :)
            w(r + 1, :) = w(r + 1, :) - k*v(r, :)
        end do
    end function kmul

    function eye(p) result(a)
        integer(ip), intent(in) :: p
        real(wp) :: a(p, p)
        integer(ip) :: r
        a = 0.0_wp
        do r = 1, p
            a(r, r) = 1.0_wp
        end do
    end function eye

end program test_eigen
