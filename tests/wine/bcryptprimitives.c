/* Test-only stand-in for Windows' bcryptprimitives.dll, for running the win64 binaries under
 * Wine 8, which lacks it (Windows 10 and later have it). Rust's standard library imports its
 * ProcessPrng (random hash-map seeds); here it draws from bcrypt.dll's system RNG, which Wine
 * has. scripts/cross-test builds it beside the win64 test executables; it never goes into an
 * FMU. */
#include <windows.h>
#include <bcrypt.h>

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T len)
{
    while (len > 0) {
        ULONG n = len > 0x40000000 ? 0x40000000 : (ULONG)len;
        if (!BCRYPT_SUCCESS(BCryptGenRandom(NULL, data, n, BCRYPT_USE_SYSTEM_PREFERRED_RNG)))
            return FALSE;
        data += n;
        len -= n;
    }
    return TRUE;
}
