// DRT_TEST_ASAN: defined when AddressSanitizer instruments the build, by GCC's macro or clang's
// feature test (clang 14 does not define GCC's).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define DRT_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DRT_TEST_ASAN 1
#endif
#endif
