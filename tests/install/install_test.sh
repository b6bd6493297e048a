#!/usr/bin/env bash
# Installs the build into a temporary prefix, checks what is installed, runs the installed CLI
# on the sample case, and builds the Debian package and checks its metadata.
# Usage: tests/install/install_test.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/usr

cmake --install "$build" --prefix "$prefix" >/dev/null
fail() { echo "install test: $*" >&2; exit 1; }
for f in bin/cranioplan bin/cranioplan-cli \
         libexec/cranioplan/cranioplan libexec/cranioplan/cranioplan-cli \
         share/man/man1/cranioplan.1 share/man/man1/cranioplan-cli.1 \
         share/applications/cranioplan.desktop \
         share/icons/hicolor/scalable/apps/cranioplan.svg \
         share/mime/packages/cranioplan.xml \
         share/doc/cranioplan/README.md share/doc/cranioplan/CHANGELOG.md \
         share/doc/cranioplan/LICENSE share/doc/cranioplan/docs/USER_GUIDE.md; do
  [ -e "$prefix/$f" ] || fail "$f was not installed"
done

# The desktop entry and the MIME type are valid, and name each other.
if command -v desktop-file-validate >/dev/null; then
  desktop-file-validate "$prefix/share/applications/cranioplan.desktop" || fail "desktop entry"
fi
mime=$(sed -n 's/.*mime-type type="\([^"]*\)".*/\1/p' "$prefix/share/mime/packages/cranioplan.xml")
grep -q "^MimeType=$mime;" "$prefix/share/applications/cranioplan.desktop" ||
  fail "the desktop entry does not open $mime"

# The man pages are man pages of these programs, with every subcommand.
grep -q '^\.TH CRANIOPLAN-CLI "1"' "$prefix/share/man/man1/cranioplan-cli.1" || fail "CLI man page"
grep -q '^\.SS autoplan' "$prefix/share/man/man1/cranioplan-cli.1" || fail "subcommands in man page"
grep -q '^\.TH CRANIOPLAN "1"' "$prefix/share/man/man1/cranioplan.1" || fail "wizard man page"

# The installed programs run (bin's launchers start libexec's programs), say their version,
# and find the sample case.
"$prefix/bin/cranioplan-cli" --version | grep -q "^cranioplan-cli [0-9]" || fail "cli --version"
QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$tmp "$prefix/bin/cranioplan" --version |
  grep -q "^Cranioplan [0-9]" || fail "wizard --version"
if [ -e /usr/share/doc/invesalius-examples/examples/Cranium.inv3 ]; then
  (cd "$tmp" && "$prefix/bin/cranioplan-cli" pipeline --sample -o "$tmp/sample" --json >"$tmp/p.json") ||
    fail "the installed CLI did not run the sample case"
  for f in skull.stl plane.json mirrored_registered.stl; do
    [ -s "$tmp/sample/$f" ] || fail "the sample case did not write $f"
  done
fi

# The Debian package: its files, and dependencies on Debian's runtime libraries.
(cd "$build" && cpack -G DEB -B "$tmp/pkg" >/dev/null) || fail "cpack"
deb=$(ls "$tmp"/pkg/*.deb)
depends=$(dpkg-deb -f "$deb" Depends)
for lib in libvtk9.1 libqt6widgets6 libopenmesh1 libgdcm libc6; do
  echo "$depends" | grep -qi "$lib" || fail "the package does not depend on $lib: $depends"
done
contents=$(dpkg-deb -c "$deb")
grep -q './usr/bin/cranioplan-cli$' <<<"$contents" || fail "the package lacks the CLI"
grep -q './usr/libexec/cranioplan/cranioplan-cli$' <<<"$contents" ||
  fail "the package lacks the program its CLI launcher starts"
grep -q './usr/share/man/man1/cranioplan.1' <<<"$contents" || fail "the package lacks man pages"
[ "$(dpkg-deb -f "$deb" Recommends)" = "invesalius-examples" ] || fail "Recommends"
echo "install test: installed, ran the sample, packaged $(basename "$deb")"
