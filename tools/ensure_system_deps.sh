#!/usr/bin/env bash
# Makes sure the system libraries for headless OpenGL 4.5 (Mesa EGL + llvmpipe) are installed.
# Silent when they are. When missing: installs them with apt-get as root, else stops with one line.
# With --test, also wants what the tests use beyond that: Xvfb (the viewer tests) and OSMesa (the
# fallback context's test); without root it only says which tests will skip and goes on.
set -euo pipefail

mesa_packages="libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri"  # libgl1: glcontext's EGL backend loads libGL.so.1

ldconfig_cache() { { command -v ldconfig >/dev/null && ldconfig -p; } || /sbin/ldconfig -p; }

mesa_present() {
    local libraries
    libraries=$(ldconfig_cache)
    grep -q 'libEGL\.so\.1 ' <<<"$libraries" && grep -q 'libEGL_mesa\.so\.0 ' <<<"$libraries" \
        && grep -q 'libGL\.so\.1 ' <<<"$libraries" || return 1
    # The software rasterizer: a DRI driver, or Mesa's gallium megadriver (Mesa >= 24).
    compgen -G '/usr/lib*/dri/swrast_dri.so' >/dev/null || compgen -G '/usr/lib/*/dri/swrast_dri.so' >/dev/null \
        || grep -q 'libgallium' <<<"$libraries"
}

apt_updated=""
apt_install() {
    [ -n "$apt_updated" ] || { apt-get update -qq; apt_updated=1; }
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}
can_install() { [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null; }

if ! mesa_present; then
    if ! can_install; then
        echo "error: Mesa's EGL/GL libraries are missing; install them (Debian/Ubuntu: apt-get install $mesa_packages)" >&2
        exit 1
    fi
    echo "installing Mesa EGL/GL libraries: $mesa_packages"
    apt_install $mesa_packages
    mesa_present || { echo "error: Mesa's EGL/GL libraries still missing after installing $mesa_packages" >&2; exit 1; }
fi

# want_for_tests NAME TESTS PACKAGE: install a missing library the tests use, or say which skip.
want_for_tests() {
    if can_install; then
        echo "installing $1 for the $2"
        apt_install "$3"
    else
        echo "note: $1 not found; the $2 will skip (Debian/Ubuntu: apt-get install $3)"
    fi
}

if [ "${1:-}" = "--test" ]; then
    command -v Xvfb >/dev/null || want_for_tests Xvfb "viewer tests" xvfb
    grep -q 'libOSMesa\.so' <<<"$(ldconfig_cache)" || want_for_tests OSMesa "OSMesa fallback test" libosmesa6
fi
