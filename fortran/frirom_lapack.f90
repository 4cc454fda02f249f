!> Explicit interfaces of the LAPACK and BLAS routines frirom calls, so that no call to
!> them goes unchecked (argument count, type, kind, rank). The signatures are those of
!> reference LAPACK 3.x with the 32-bit integer ABI that Debian's OpenBLAS and reference
!> LAPACK libraries export (`ilp` below); arrays are assumed-size, as LAPACK declares them,
!> so callers pass whole arrays, contiguous sections or a first element.
!>
!> Add a routine here before calling it anywhere in the library. ARPACK and MUMPS are
!> not LAPACK: their interfaces stay with their only caller, frirom_eigen.
module frirom_lapack
    use, intrinsic :: iso_fortran_env, only: int32
    use frirom_kinds, only: wp
    implicit none
    private
    public :: ilp
    public :: dgemm, zgemm
    public :: dgetrf, dgetrs, dpotrf, dpotrs, dgeev
    public :: dgbtrf, dgbtrs, zgbtrf, zgbtrs

    !> Integer kind of LAPACK's INTEGER arguments (LP64 ABI: 32 bits).
    integer, parameter :: ilp = int32

    ! ---- BLAS level 3 -----------------------------------------------------------------
    interface
        !> C = alpha op(A) op(B) + beta C, real.
        pure subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
            import :: wp, ilp
            character, intent(in) :: transa, transb         !! 'N', 'T' or 'C'
            integer(ilp), intent(in) :: m, n, k, lda, ldb, ldc
            real(wp), intent(in) :: alpha, beta
            real(wp), intent(in) :: a(lda, *), b(ldb, *)
            real(wp), intent(inout) :: c(ldc, *)            !! (m, n)
        end subroutine dgemm

        !> C = alpha op(A) op(B) + beta C, complex.
        pure subroutine zgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
            import :: wp, ilp
            character, intent(in) :: transa, transb         !! 'N', 'T' or 'C'
            integer(ilp), intent(in) :: m, n, k, lda, ldb, ldc
            complex(wp), intent(in) :: alpha, beta
            complex(wp), intent(in) :: a(lda, *), b(ldb, *)
            complex(wp), intent(inout) :: c(ldc, *)         !! (m, n)
        end subroutine zgemm
    end interface

    ! ---- dense LU, Cholesky and eigenvalues ---------------------------------------------
    interface
        !> LU factorisation with partial pivoting of a general m x n matrix, in place.
        pure subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: wp, ilp
            integer(ilp), intent(in) :: m, n, lda
            real(wp), intent(inout) :: a(lda, *)            !! (m, n) A in, L and U out
            integer(ilp), intent(out) :: ipiv(*)            !! (min(m, n)) pivots
            integer(ilp), intent(out) :: info               !! > 0: zero pivot U(info, info)
        end subroutine dgetrf

        !> Solve op(A) X = B with the factorisation of dgetrf.
        pure subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp, ilp
            character, intent(in) :: trans
            integer(ilp), intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(in) :: a(lda, *)               !! (n, n) factors
            integer(ilp), intent(in) :: ipiv(*)             !! (n)
            real(wp), intent(inout) :: b(ldb, *)            !! (n, nrhs) B in, X out
            integer(ilp), intent(out) :: info
        end subroutine dgetrs

        !> Cholesky factorisation of a symmetric positive definite matrix, in place.
        pure subroutine dpotrf(uplo, n, a, lda, info)
            import :: wp, ilp
            character, intent(in) :: uplo                   !! 'U' or 'L'
            integer(ilp), intent(in) :: n, lda
            real(wp), intent(inout) :: a(lda, *)            !! (n, n)
            integer(ilp), intent(out) :: info               !! > 0: not positive definite
        end subroutine dpotrf

        !> Solve A X = B with the Cholesky factor of dpotrf.
        pure subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
            import :: wp, ilp
            character, intent(in) :: uplo
            integer(ilp), intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(in) :: a(lda, *)               !! (n, n) factor
            real(wp), intent(inout) :: b(ldb, *)            !! (n, nrhs) B in, X out
            integer(ilp), intent(out) :: info
        end subroutine dpotrs

        !> Eigenvalues (and optionally eigenvectors) of a general real matrix; lwork = -1
        !> returns the optimal workspace size in work(1).
        pure subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, &
                              lwork, info)
            import :: wp, ilp
            character, intent(in) :: jobvl, jobvr           !! 'N' or 'V'
            integer(ilp), intent(in) :: n, lda, ldvl, ldvr, lwork
            real(wp), intent(inout) :: a(lda, *)            !! (n, n), overwritten
            real(wp), intent(out) :: wr(*), wi(*)           !! (n) eigenvalues, Re and Im
            real(wp), intent(out) :: vl(ldvl, *), vr(ldvr, *)
            real(wp), intent(out) :: work(*)                !! (max(1, lwork))
            integer(ilp), intent(out) :: info
        end subroutine dgeev
    end interface

    ! ---- banded LU ----------------------------------------------------------------------
    interface
        !> LU factorisation of a real banded matrix in LAPACK band storage, in place.
        pure subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp, ilp
            integer(ilp), intent(in) :: m, n, kl, ku, ldab
            real(wp), intent(inout) :: ab(ldab, *)          !! (2 kl + ku + 1, n)
            integer(ilp), intent(out) :: ipiv(*)            !! (min(m, n))
            integer(ilp), intent(out) :: info
        end subroutine dgbtrf

        !> Solve op(A) X = B with the banded factorisation of dgbtrf.
        pure subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp, ilp
            character, intent(in) :: trans
            integer(ilp), intent(in) :: n, kl, ku, nrhs, ldab, ldb
            real(wp), intent(in) :: ab(ldab, *)
            integer(ilp), intent(in) :: ipiv(*)
            real(wp), intent(inout) :: b(ldb, *)            !! (n, nrhs) B in, X out
            integer(ilp), intent(out) :: info
        end subroutine dgbtrs

        !> LU factorisation of a complex banded matrix in LAPACK band storage, in place.
        pure subroutine zgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp, ilp
            integer(ilp), intent(in) :: m, n, kl, ku, ldab
            complex(wp), intent(inout) :: ab(ldab, *)       !! (2 kl + ku + 1, n)
            integer(ilp), intent(out) :: ipiv(*)            !! (min(m, n))
            integer(ilp), intent(out) :: info
        end subroutine zgbtrf

        !> Solve op(A) X = B with the banded factorisation of zgbtrf.
        pure subroutine zgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp, ilp
            character, intent(in) :: trans
            integer(ilp), intent(in) :: n, kl, ku, nrhs, ldab, ldb
            complex(wp), intent(in) :: ab(ldab, *)
            integer(ilp), intent(in) :: ipiv(*)
            complex(wp), intent(inout) :: b(ldb, *)         !! (n, nrhs) B in, X out
            integer(ilp), intent(out) :: info
        end subroutine zgbtrs
    end interface
end module frirom_lapack
