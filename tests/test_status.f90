!> Every status code has its own message and the unknown code is reported as such.
program test_status
    use frirom_kinds, only: ip
    use frirom_status
    implicit none
    integer(ip) :: i, j
    character(len=200) :: msgs(0:12)
    do i = 0, 12
        msgs(i) = frirom_status_message(i)
        if (msgs(i) == 'unknown status code') error stop 'a status code has no message'
        do j = 0, i - 1
            if (msgs(i) == msgs(j)) error stop 'two status codes share a message'
        end do
    end do
    if (frirom_status_message(999_ip) /= 'unknown status code') error stop 'code 999 known?'
    print '(a)', 'test_status: ok'
end program test_status
