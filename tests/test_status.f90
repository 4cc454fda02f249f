!> Every status code has its own message, frirom_status_code gives each code back from its
!> name, and the unknown code and name are reported as such.
program test_status
    use frirom_kinds, only: ip
    use frirom_check, only: check, check_done
    use frirom_status
    implicit none
    integer(ip), parameter :: codes(*) = [FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
        FRIROM_ERR_NONFINITE, FRIROM_ERR_SAMPLES, FRIROM_ERR_ALLOC, FRIROM_ERR_FFTW, &
        FRIROM_ERR_LAPACK, FRIROM_ERR_ARPACK, FRIROM_ERR_NOCONV, FRIROM_ERR_SINGULAR, &
        FRIROM_ERR_LAW, FRIROM_ERR_NOCLOSE, FRIROM_ERR_CONT, FRIROM_ERR_MODEL, FRIROM_ERR_FACTOR]
    !> The names of `codes`, in the same order.
    character(len=*), parameter :: names(*) = [character(len=20) :: 'FRIROM_OK', &
        'FRIROM_ERR_SIZE', 'FRIROM_ERR_PARAM', 'FRIROM_ERR_NONFINITE', 'FRIROM_ERR_SAMPLES', &
        'FRIROM_ERR_ALLOC', 'FRIROM_ERR_FFTW', 'FRIROM_ERR_LAPACK', 'FRIROM_ERR_ARPACK', &
        'FRIROM_ERR_NOCONV', 'FRIROM_ERR_SINGULAR', 'FRIROM_ERR_LAW', 'FRIROM_ERR_NOCLOSE', &
        'FRIROM_ERR_CONT', 'FRIROM_ERR_MODEL', 'FRIROM_ERR_FACTOR']
    integer(ip) :: i, j
    character(len=200) :: msgs(size(codes))
    call check(size(names) == size(codes), 'one name per code')
    do i = 1, size(codes)
        msgs(i) = frirom_status_message(codes(i))
        call check(msgs(i) /= 'unknown status code', trim(names(i))//' has no message')
        call check(frirom_status_code(trim(names(i))) == codes(i), &
                   'frirom_status_code('//trim(names(i))//') is not its code')
        do j = 1, i - 1
            call check(codes(i) /= codes(j), trim(names(i))//' shares a value')
            call check(msgs(i) /= msgs(j), trim(names(i))//' shares a message')
        end do
    end do
    call check(frirom_status_message(999_ip) == 'unknown status code', 'code 999 known?')
    call check(frirom_status_code('FRIROM_ERR_NONE') == -1, 'an unknown name must give -1')
    call check_done('test_status')
end program test_status
