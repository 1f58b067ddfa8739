# The hardening flags Debian builds its packages with (bookworm's dpkg-buildflags with
# DEB_BUILD_MAINT_OPTIONS=hardening=+all, the same on amd64, arm64 and armhf):
#   -fstack-protector-strong          a canary in every function with an array or an address-taken local
#   -D_FORTIFY_SOURCE=2               glibc checks the sizes it can see in memcpy, snprintf, read, ...
#   -Wl,-z,relro -Wl,-z,now           the GOT read-only after start-up, every symbol bound at load
# (position-independent executables are already the compiler's default on Debian). Without them
# lintian noted hardening-no-fortify-functions and hardening-no-bindnow on the package.
# On by default: the tests then run the code the package ships (none of these flags changes how
# floating-point arithmetic is compiled), and scripts/package.sh packages the tree the tests built without
# compiling it again. Ignored in sanitizer and fuzzing builds, which instrument memory
# accesses themselves.
option(GYROD_HARDENING "Build with Debian's hardening flags (stack protector, fortify, relro, bindnow)" ON)
set(GYROD_HARDENED OFF)  # whether the flags apply: tests/ checks the binaries then
if(GYROD_HARDENING AND NOT GYROD_SANITIZE AND NOT GYROD_FUZZ)
  set(GYROD_HARDENED ON)
  add_compile_options(-fstack-protector-strong)
  # glibc's fortified functions need optimisation (features.h warns without it): not in Debug.
  # -U first: a compiler that defines it by itself (Ubuntu's gcc) would warn about a redefinition.
  add_compile_options("$<$<NOT:$<CONFIG:Debug>>:-U_FORTIFY_SOURCE;-D_FORTIFY_SOURCE=2>")
  add_link_options(LINKER:-z,relro LINKER:-z,now)
endif()
