#!/bin/sh
# `meson install` gives a C library and a Lua module a new user can use:
# installed into a scratch DESTDIR, the header and seixo.pc build and link a
# C program against the shared libseixo, and Debian's stock lua5.4 loads the
# module with `require "seixo"` (and the pure-Lua library beside it) from
# LUA_CPATH / LUA_PATH alone, with no seixo executable involved.
#   install.sh BUILDDIR PREFIX LIBDIR SANITIZE
set -eu
build=$1 prefix=$2 libdir=$3 sanitize=$4
dest=$(mktemp -d)
trap 'rm -rf "$dest"' EXIT
meson install -C "$build" --destdir "$dest" --no-rebuild --quiet > "$dest/install.log" 2>&1 || {
    cat "$dest/install.log"; exit 1; }
root=$dest$prefix
case $libdir in /*) lib=$dest$libdir ;; *) lib=$root/$libdir ;; esac
for f in "$root/include/seixo/seixo.h" "$lib/libseixo.so" "$lib/pkgconfig/seixo.pc" "$root/lib/lua/5.4/seixo.so" \
         "$root/share/lua/5.4/seixo/lab.lua" "$root/share/lua/5.4/seixo/lab/series.lua" "$root/share/lua/5.4/seixo/help.lua" \
         "$root/bin/seixo" "$root/share/seixo/render" "$root/share/seixo/render.py" "$root/share/seixo/xvfb.sh"; do
    [ -f "$f" ] || { echo "not installed: $f"; find "$dest" -type f; exit 1; }
done
# `seixo render` finds its script in the installed share/seixo (a first
# check, needing no ParaView: the usage; tests/io/render.sh renders)
err=$(LD_LIBRARY_PATH="$lib" "$root/bin/seixo" render 2>&1) && { echo "seixo render without arguments succeeded"; exit 1; }
case $err in "usage: seixo render SERIES.xmf OUT.png [SNAPSHOT]"*) ;; *) echo "seixo render: $err"; exit 1 ;; esac
# a static libseixo.a is no longer what is installed
[ ! -e "$lib/libseixo.a" ] || { echo "libseixo.a is installed"; exit 1; }

# a C program through pkg-config (the .pc's prefix moved to the DESTDIR)
flags=$(PKG_CONFIG_PATH="$lib/pkgconfig" pkg-config --define-variable=prefix="$root" --cflags --libs seixo)
cat > "$dest/fall.c" <<'C'
#include <seixo.h>
#include <stdio.h>
int main(void)
{
    sx_model_def d = sx_model_default_def();
    d.dim = 3;
    d.gravity[2] = -9.81;
    sx_model *m = sx_model_create(&d, NULL, 0);
    sx_material_def md = sx_material_default_def();
    int mat;
    sx_ball_def b = sx_ball_default_def();
    b.radius = 0.01;
    int64_t id;
    if (!m || sx_material_set(m, "glass", &md, &mat) != SX_OK || (b.material = mat, sx_ball_add(m, &b, &id)) != SX_OK ||
        sx_model_set_timestep(m, 1e-4) != SX_OK || sx_model_cycle(m, 100) != SX_OK) return 1;
    double v[3];
    sx_ball_get_vec(m, id, SX_BALL_VEL, v);
    printf("vz %.6f\n", v[2]);
    sx_model_destroy(m);
    return 0;
}
C
# a sanitized library links its runtime into the program too
[ "$sanitize" = "none" ] || flags="$flags -fsanitize=$sanitize"
# shellcheck disable=SC2086
cc -o "$dest/fall" "$dest/fall.c" $flags
out=$(LD_LIBRARY_PATH="$lib" "$dest/fall")
[ "$out" = "vz -0.098100" ] || { echo "the C program printed '$out', expected 'vz -0.098100' (100 steps of 1e-4 s under g)"; exit 1; }
echo "C: $out"

if [ "$sanitize" != "none" ]; then
    echo "stock lua5.4 skipped: a sanitized module cannot load into an unsanitized interpreter"
    exit 0
fi
if ! command -v lua5.4 > /dev/null; then
    echo "lua5.4 not installed (apt-get install lua5.4): skipped"
    exit 77
fi
out=$(cd "$dest" && LUA_CPATH="$root/lib/lua/5.4/?.so" LUA_PATH="$root/share/lua/5.4/?.lua" lua5.4 -e '
local seixo = require "seixo"
local m = seixo.model{dim = 2, gravity = {0, -9.81}, timestep = 1e-4}
m:material("glass", {density = 2500})
local b = m:ball{pos = {0, 1}, radius = 0.01}
m:cycle(100)
local lab = require "seixo.lab"
print(seixo.version, string.format("%.6f", b.vel[2]), type(lab.triaxial), #seixo.models())
' 2>&1)
[ "$out" = "0.1.0	-0.098100	function	1" ] || { echo "stock lua5.4 printed: $out"; exit 1; }
echo "lua5.4: $out"
