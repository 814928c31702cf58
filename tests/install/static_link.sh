#!/bin/sh
# Static embedding of the installed library, as a user does it: install into a scratch
# directory, compile the README's example with `pkg-config --static`, run it.
# usage: static_link.sh BUILD_DIR SOURCE_DIR
# A fully static binary (-static) needs a static archive of every dependency. Debian ships
# none for METIS (used by CHOLMOD, which UMFPACK's orderings use too): then everything that
# has an archive (libfesd, SuiteSparse, OpenBLAS, gfortran, gomp) is linked statically and
# only METIS and the C library dynamically; ldd must show no other shared library.
set -eu
B=$(cd "$1" && pwd); S=$(cd "$2" && pwd)
D=$(mktemp -d); trap 'rm -rf "$D"' EXIT
meson install -C "$B" --no-rebuild --destdir "$D" >/dev/null
pc=$(find "$D" -name fesd.pc | head -n 1)
prefix=$(sed -n 's/^prefix=//p' "$pc")
export PKG_CONFIG_PATH="$(dirname "$pc")"
PC="pkg-config --define-variable=prefix=$D$prefix"
python3 "$S/tools/extract_example.py" "$S/README.md" "$D/app.c"
cflags=$($PC --cflags fesd); libs=$($PC --static --libs fesd)
if cc "$D/app.c" $cflags $libs -static -o "$D/app" 2>"$D/err"; then
  echo "fully static: cc app.c \$(pkg-config --cflags --static --libs fesd) -static"
else
  missing=$(grep -o 'cannot find -l[a-z0-9_]*' "$D/err" | sed 's/cannot find //' | sort -u | tr '\n' ' ')
  echo "fully static link impossible here, no static archive for: $missing"
  for m in $missing; do [ "$m" = "-lmetis" ] || { cat "$D/err"; exit 1; }; done
  slibs=$(echo "$libs" | tr ' ' '\n' | grep -v -x -e '-lmetis' -e '-lm' -e '-lpthread' | tr '\n' ' ')
  cc "$D/app.c" $cflags -Wl,-Bstatic $slibs -lquadmath -Wl,-Bdynamic -lmetis -lm -lpthread -o "$D/app"
  echo "static except METIS and libc: cc app.c \$(pkg-config --cflags fesd) -Wl,-Bstatic <--static libs without -lmetis> -lquadmath -Wl,-Bdynamic -lmetis -lm"
fi
shared=$(ldd "$D/app" 2>&1 | grep -o 'lib[a-z0-9_]*\.so' | grep -v -x -e libc.so -e libm.so -e libmetis.so -e ld-linux-x86-64.so -e libdl.so -e libpthread.so || true)
if [ -n "$shared" ]; then echo "FAIL: shared libraries left: $shared"; exit 1; fi
echo "shared libraries: $(ldd "$D/app" 2>&1 | grep -o "lib[a-z0-9_-]*\.so[.0-9]*" | sort -u | tr '\n' ' ')"
"$D/app"
