#!/bin/sh
# Runs the XSD validation test (cargo feature `xsd`, fmi-rs `schema`) with the
# system libxml2 (Debian: libxml2-dev, libicu-dev, zlib1g-dev, liblzma-dev).
# fmi-rs's build script otherwise downloads libxml2 from GitHub and builds it
# with cmake; it skips that when OUT_DIR/libxml2 exists, so the first build
# attempt creates OUT_DIR and the system library is linked into it.
set -e
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-target}"
if ! cargo test --features xsd --test fmi_model_description --no-run >/dev/null 2>&1; then
    for out in "$target"/debug/build/fmi-rs-*/out; do
        mkdir -p "$out/libxml2/include" "$out/libxml2/lib"
        ln -sfn /usr/include/libxml2 "$out/libxml2/include/libxml2"
        ln -sf "$(ls /usr/lib/*/libxml2.a /usr/lib/libxml2.a 2>/dev/null | head -1)" "$out/libxml2/lib/libxml2.a"
    done
fi
exec cargo test --features xsd --test fmi_model_description "$@"
