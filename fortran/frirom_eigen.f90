!> Sparse symmetric eigen-solves and linear solves for model reduction.
!!
!! K phi = lambda M phi for the few eigenvalues nearest a shift sigma, by ARPACK's
!! implicitly restarted Lanczos (dsaupd/dseupd) in shift-invert mode (mode 3):
!! OP = (K - sigma M)^-1 M, B = M. The factorisation of K - sigma M is MUMPS's sparse
!! multifrontal LDL^T (sequential library) with a nested-dissection ordering, which keeps
!! the fill of 3-D solid meshes far below that of a banded factor. The same factor serves
!! static solves with many right-hand sides (Craig-Bampton constraint modes).
!!
!! Matrices come as the upper triangle in coordinate form (1-based, duplicates summed)
!! for the factorisation, and M also in full CSR form for fast products. All state lives
!! in an `eigen_work` the caller owns.
module frirom_eigen
    use frirom_kinds, only: wp, ip
    use frirom_zsparse, only: mumps_status
    use frirom_status, only: set_status, FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_NONFINITE, FRIROM_ERR_ALLOC, FRIROM_ERR_ARPACK, &
                             FRIROM_ERR_NOCONV, FRIROM_ERR_SINGULAR, FRIROM_ERR_FACTOR
    use frirom_arpack, only: dsaupd, dseupd
    implicit none
    private
    public :: eigen_work, eigen_factor, eigen_solve, eigen_modes, eigen_destroy, csr_symv

    include 'dmumps_struc.h'

    !> Factorisation of K - sigma M and the buffers the solves need.
    type :: eigen_work
        type(dmumps_struc) :: mumps          !! MUMPS instance (sequential)
        logical :: initialised = .false.     !! mumps JOB=-1 done
        logical :: factored = .false.        !! mumps JOB=4 done
        integer(ip) :: n = 0                 !! order of the matrix
        real(wp) :: sigma = 0.0_wp           !! shift of the factored matrix
    end type eigen_work

contains

    !> Factor A = K - sigma M (both upper-triangle coordinate lists, 1-based).
    !! An earlier factor held by `work` is released first.
    subroutine eigen_factor(work, n, krow, kcol, kval, mrow, mcol, mval, sigma, info, errmsg)
        type(eigen_work), intent(inout) :: work  !! workspace owned by the caller
        integer(ip), intent(in) :: n             !! matrix order
        integer(ip), intent(in) :: krow(:), kcol(:)  !! K entries (nnz_k), row <= col
        real(wp), intent(in) :: kval(:)          !! K values (nnz_k)
        integer(ip), intent(in) :: mrow(:), mcol(:)  !! M entries (nnz_m), row <= col
        real(wp), intent(in) :: mval(:)          !! M values (nnz_m)
        real(wp), intent(in) :: sigma            !! shift
        integer(ip), intent(out) :: info         !! status (0 = ok)
        character(len=*), intent(inout), optional :: errmsg
        integer(ip) :: nk, nm, nz, stat, attempt
        character(len=160) :: buf

        info = FRIROM_OK
        nk = size(krow)
        nm = size(mrow)
        if (n < 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'eigen_factor: matrix order < 1')
            return
        end if
        if (size(kcol) /= nk .or. size(kval) /= nk .or. size(mcol) /= nm &
            .or. size(mval) /= nm) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, &
                            'eigen_factor: row, col and value lists differ in length')
            return
        end if
        if (nk > 0) then
            if (minval(krow) < 1 .or. maxval(krow) > n .or. minval(kcol) < 1 &
                .or. maxval(kcol) > n) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, &
                                'eigen_factor: K index outside 1..n')
                return
            end if
        end if
        if (nm > 0) then
            if (minval(mrow) < 1 .or. maxval(mrow) > n .or. minval(mcol) < 1 &
                .or. maxval(mcol) > n) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, &
                                'eigen_factor: M index outside 1..n')
                return
            end if
        end if
        if (.not. all(ieee_finite(kval)) .or. .not. all(ieee_finite(mval)) &
            .or. .not. ieee_finite(sigma)) then
            call set_status(info, FRIROM_ERR_NONFINITE, errmsg, &
                            'eigen_factor: K, M or sigma holds NaN or Inf')
            return
        end if
        call eigen_destroy(work)

        work%mumps%comm = 0
        work%mumps%par = 1
        ! LDL^T for an indefinite shifted matrix, Cholesky-like LDL^T when sigma <= 0.
        work%mumps%sym = merge(1, 2, sigma <= 0.0_wp)
        work%mumps%job = -1
        call dmumps(work%mumps)
        if (work%mumps%infog(1) < 0) then
            call mumps_status('dmumps', work%mumps%infog(1), work%mumps%infog(2), 'init', &
                              info, errmsg)
            return
        end if
        work%initialised = .true.
        work%mumps%icntl(1:4) = [-1, -1, -1, 0]   ! silent
        work%mumps%icntl(7) = 7                   ! automatic ordering choice
        work%n = n
        work%sigma = sigma
        nz = nk + merge(nm, 0, sigma /= 0.0_wp)
        work%mumps%n = n
        work%mumps%nnz = int(nz, kind=8)
        allocate (work%mumps%irn(nz), work%mumps%jcn(nz), work%mumps%a(nz), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'eigen_factor: matrix copy')
            return
        end if
        work%mumps%irn(1:nk) = krow
        work%mumps%jcn(1:nk) = kcol
        work%mumps%a(1:nk) = kval
        if (nz > nk) then
            work%mumps%irn(nk + 1:nz) = mrow
            work%mumps%jcn(nk + 1:nz) = mcol
            work%mumps%a(nk + 1:nz) = -sigma*mval
        end if
        do attempt = 1, 3
            work%mumps%job = 4                    ! analysis + factorisation
            call dmumps(work%mumps)
            ! -8, -9, -11, -12, -14, -15: workspace estimate too small; relax and retry.
            if (any(work%mumps%infog(1) == [-8, -9, -11, -12, -14, -15])) then
                work%mumps%icntl(14) = 2*max(work%mumps%icntl(14), 20)
                cycle
            end if
            exit
        end do
        if (work%mumps%infog(1) == -10) then
            write (buf, '(a,i0,a)') 'eigen_factor: dmumps: K - sigma M is singular (rank ', &
                work%mumps%infog(2), '); choose another shift or constrain rigid-body modes'
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, trim(buf))
            return
        else if (work%mumps%infog(1) < 0) then
            call mumps_status('dmumps', work%mumps%infog(1), work%mumps%infog(2), &
                              'factorisation', info, errmsg)
            return
        end if
        work%factored = .true.
    end subroutine eigen_factor

    !> Overwrite b(n, nrhs) with (K - sigma M)^-1 b using the factor held by `work`.
    subroutine eigen_solve(work, b, info, errmsg)
        type(eigen_work), intent(inout) :: work  !! a factored workspace
        real(wp), intent(inout), target, contiguous :: b(:, :)  !! (n, nrhs) rhs -> solution
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg

        info = FRIROM_OK
        if (.not. work%factored) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'eigen_solve: nothing factored')
            return
        end if
        if (size(b, 1) /= work%n) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, &
                            'eigen_solve: right-hand side rows /= matrix order')
            return
        end if
        if (size(b, 2) == 0) return
        work%mumps%rhs(1:size(b)) => b
        work%mumps%nrhs = size(b, 2)
        work%mumps%lrhs = work%n
        work%mumps%job = 3
        call dmumps(work%mumps)
        nullify (work%mumps%rhs)
        if (work%mumps%infog(1) < 0) then
            call mumps_status('dmumps', work%mumps%infog(1), work%mumps%infog(2), 'solve', &
                              info, errmsg)
        end if
    end subroutine eigen_solve

    !> The nev eigenpairs of K phi = lambda M phi nearest the shift of the factor in `work`.
    !! Eigenvalues come in ascending order, eigenvectors M-orthonormal.
    subroutine eigen_modes(work, mptr, mind, mval, nev, lambda, phi, info, errmsg, &
                           ncv, tol, maxiter, iterations)
        type(eigen_work), intent(inout) :: work  !! factored at the wanted shift
        integer(ip), intent(in) :: mptr(:)       !! M full CSR row pointers (n+1), 1-based
        integer(ip), intent(in) :: mind(:)       !! M column indices (nnz), 1-based
        real(wp), intent(in) :: mval(:)          !! M values (nnz)
        integer(ip), intent(in) :: nev           !! number of eigenpairs wanted
        real(wp), intent(out) :: lambda(:)       !! (nev) eigenvalues [rad^2/s^2]
        real(wp), intent(out) :: phi(:, :)       !! (n, nev) eigenvectors
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer(ip), intent(in), optional :: ncv      !! Lanczos basis size (default 1.3 nev+10)
        real(wp), intent(in), optional :: tol         !! ARPACK relative tolerance (default 0)
        integer(ip), intent(in), optional :: maxiter  !! restarts allowed (default 500)
        integer(ip), intent(out), optional :: iterations  !! restarts used

        integer :: ido, iparam(11), ipntr(11), ainfo, lworkl, n, nc, stat, k
        integer(8) :: seed
        real(wp) :: atol
        real(wp), allocatable :: resid(:), v(:, :), workd(:), workl(:), d(:), tmp(:, :)
        logical, allocatable :: sel(:)
        integer, allocatable :: order(:)
        character(len=200) :: buf

        info = FRIROM_OK
        n = work%n
        if (.not. work%factored) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'eigen_modes: nothing factored')
            return
        end if
        if (size(mptr) /= n + 1 .or. size(mind) /= size(mval) .or. size(lambda) /= nev &
            .or. size(phi, 1) /= n .or. size(phi, 2) /= nev) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, &
                            'eigen_modes: M, lambda or phi has the wrong size')
            return
        end if
        if (nev < 1 .or. nev >= n - 1) then
            write (buf, '(a,i0,a,i0)') 'eigen_modes: nev must be in 1..n-2; nev = ', nev, &
                ', n = ', n
            call set_status(info, FRIROM_ERR_PARAM, errmsg, trim(buf))
            return
        end if
        if (mptr(1) /= 1 .or. mptr(n + 1) /= size(mind) + 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, &
                            'eigen_modes: M row pointers must run from 1 to nnz+1')
            return
        end if
        if (minval(mind) < 1 .or. maxval(mind) > n) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, &
                            'eigen_modes: M column index outside 1..n')
            return
        end if
        ! nev + 30 % + 10: in shift-invert mode the OP count hardly depends on ncv (about
        ! 2.5 nev for nev = 50..200 on solid meshes), while ARPACK's orthogonalisation
        ! costs n ncv^2 per pass: the usual 2 nev + 20 is twice as expensive for nothing.
        nc = min(n, nev + (3*nev)/10 + 10)
        if (present(ncv)) then
            if (ncv > nev .and. ncv <= n) nc = ncv
        end if
        atol = 0.0_wp
        if (present(tol)) atol = tol
        lworkl = nc*(nc + 8)
        allocate (resid(n), v(n, nc), workd(3*n), workl(lworkl), d(nev), sel(nc), &
                  stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'eigen_modes: Lanczos basis')
            return
        end if
        iparam = 0
        iparam(1) = 1                     ! exact shifts
        iparam(3) = 500
        if (present(maxiter)) iparam(3) = maxiter
        iparam(7) = 3                     ! shift-invert
        ipntr = 0
        ido = 0
        ! a fixed start vector (info = 1): ARPACK's own random one comes from a seed that
        ! persists across calls, so the modes would depend on what ran before in the process
        seed = 20261121_8
        do k = 1, n                       ! Park-Miller minimal standard generator
            seed = modulo(16807_8*seed, 2147483647_8)
            resid(k) = real(seed, wp)/2147483647.0_wp - 0.5_wp
        end do
        ainfo = 1
        do
            call dsaupd(ido, 'G', n, 'LM', nev, atol, resid, nc, v, n, iparam, ipntr, &
                        workd, workl, lworkl, ainfo)
            select case (ido)
            case (-1)
                call csr_symv(mptr, mind, mval, workd(ipntr(1):ipntr(1) + n - 1), &
                              workd(ipntr(2):ipntr(2) + n - 1))
                call solve_vec(workd(ipntr(2):ipntr(2) + n - 1))
            case (1)
                workd(ipntr(2):ipntr(2) + n - 1) = workd(ipntr(3):ipntr(3) + n - 1)
                call solve_vec(workd(ipntr(2):ipntr(2) + n - 1))
            case (2)
                call csr_symv(mptr, mind, mval, workd(ipntr(1):ipntr(1) + n - 1), &
                              workd(ipntr(2):ipntr(2) + n - 1))
            case default
                exit
            end select
            if (info /= FRIROM_OK) return
        end do
        if (present(iterations)) iterations = iparam(3)
        if (ainfo == 1) then
            write (buf, '(a,i0,a,i0,a)') 'eigen_modes: dsaupd: ', iparam(5), ' of ', nev, &
                ' eigenpairs converged within the allowed restarts; raise maxiter or ncv'
            call set_status(info, FRIROM_ERR_NOCONV, errmsg, trim(buf))
            return
        else if (ainfo /= 0) then
            write (buf, '(a,i0)') 'eigen_modes: dsaupd returned info = ', ainfo
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, trim(buf))
            return
        end if
        call dseupd(.true., 'A', sel, d, phi, n, work%sigma, 'G', n, 'LM', nev, atol, resid, &
                    nc, v, n, iparam, ipntr, workd, workl, lworkl, ainfo)
        if (ainfo /= 0) then
            write (buf, '(a,i0)') 'eigen_modes: dseupd returned info = ', ainfo
            call set_status(info, FRIROM_ERR_ARPACK, errmsg, trim(buf))
            return
        end if
        ! Ascending order (dseupd already gives it; keep it explicit and cheap).
        allocate (order(nev))
        order = [(k, k=1, nev)]
        call sort_index(d, order)
        lambda = d(order)
        if (any(order /= [(k, k=1, nev)])) then
            allocate (tmp(n, nev))
            tmp = phi(:, order)
            phi = tmp
        end if

    contains

        subroutine solve_vec(x)
            real(wp), intent(inout), target, contiguous :: x(:)
            real(wp), pointer, contiguous :: x2(:, :)
            x2(1:n, 1:1) => x
            call eigen_solve(work, x2, info, errmsg)
        end subroutine solve_vec

    end subroutine eigen_modes

    !> y = A x for a square matrix in full CSR storage (1-based).
    pure subroutine csr_symv(ptr, ind, val, x, y)
        integer(ip), intent(in) :: ptr(:)  !! (n+1) row pointers
        integer(ip), intent(in) :: ind(:)  !! (nnz) column indices
        real(wp), intent(in) :: val(:)     !! (nnz) values
        real(wp), intent(in) :: x(:)       !! (n)
        real(wp), intent(out) :: y(:)      !! (n)
        integer(ip) :: i, k
        real(wp) :: s
        do i = 1, size(ptr) - 1
            s = 0.0_wp
            do k = ptr(i), ptr(i + 1) - 1
                s = s + val(k)*x(ind(k))
            end do
            y(i) = s
        end do
    end subroutine csr_symv

    !> Release the factor and buffers held by `work`.
    subroutine eigen_destroy(work)
        type(eigen_work), intent(inout) :: work
        if (work%initialised) then
            if (associated(work%mumps%irn)) deallocate (work%mumps%irn)
            if (associated(work%mumps%jcn)) deallocate (work%mumps%jcn)
            if (associated(work%mumps%a)) deallocate (work%mumps%a)
            nullify (work%mumps%rhs)
            work%mumps%job = -2
            call dmumps(work%mumps)
        end if
        work%initialised = .false.
        work%factored = .false.
        work%n = 0
    end subroutine eigen_destroy

    !> Insertion sort of an index vector by key (nev is small).
    pure subroutine sort_index(key, idx)
        real(wp), intent(in) :: key(:)
        integer, intent(inout) :: idx(:)
        integer :: i, j, t
        do i = 2, size(idx)
            t = idx(i)
            j = i - 1
            do while (j >= 1)
                if (key(idx(j)) <= key(t)) exit
                idx(j + 1) = idx(j)
                j = j - 1
            end do
            idx(j + 1) = t
        end do
    end subroutine sort_index

    elemental logical function ieee_finite(x)
        use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
        real(wp), intent(in) :: x
        ieee_finite = ieee_is_finite(x)
    end function ieee_finite

end module frirom_eigen
