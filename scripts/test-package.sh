#!/usr/bin/env bash
# Builds the amd64 package (scripts/package.sh) and takes it through its life on this machine,
# as root: install with apt-get, check what it installed, run gyrod from /usr/sbin on the mock
# with gyroctl reading a RATE line, reinstall (a changed conffile is kept), remove (the conffile
# stays), purge (nothing of the package stays). Works whether or not PID 1 is systemd.
# The gyrod user and the i2c and gpio groups stay after the purge, as Debian leaves system users
# (files they owned may remain); the script says so and checks they exist.
# A gyrod package already installed is purged first. Exits non-zero at the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
started=$(date +%s)
[ "$(id -u)" -eq 0 ] || {
  echo "test-package: run as root (it installs and purges the package)" >&2
  exit 1
}
export DEBIAN_FRONTEND=noninteractive
fail() {
  echo "test-package: FAIL: $*" >&2
  exit 1
}
ok() { echo "test-package: ok: $* [$(($(date +%s) - started)) s]"; }
# apt-get, waiting for another apt or dpkg run to finish (plain dpkg would fail on the lock).
apt_get() { apt-get -y -qq -o DPkg::Lock::Timeout=600 "$@" >/dev/null 2>"$work_dir/apt.log" || {
  cat "$work_dir/apt.log" >&2
  return 1
}; }
work_dir=$(mktemp -d)
chmod 0755 "$work_dir" # user gyrod reaches its socket folder inside
trap 'rm -rf "$work_dir"' EXIT

if dpkg-query -W -f='${Status}' gyrod 2>/dev/null | grep -qv 'not-installed'; then
  echo "test-package: purging the gyrod package installed before"
  apt_get purge gyrod
fi

deb=$(scripts/package.sh amd64 | tail -1)
version=$(dpkg-deb -f "$deb" Version)
ok "built $deb ($(($(date +%s) - started)) s)"
# lintian when installed (not a build dependency): errors and warnings fail.
if command -v lintian >/dev/null 2>&1; then
  lintian --fail-on error,warning "$deb" || fail "lintian $deb"
  ok "lintian: no error or warning"
fi

apt_get install "./$deb" || fail "apt-get install ./$deb"
[ "$(dpkg-query -W -f='${Status}' gyrod)" = "install ok installed" ] || fail "gyrod is not 'install ok installed'"
ok "installed gyrod $version"

# The programs.
[ "$(/usr/sbin/gyrod --version)" = "gyrod $version" ] || fail "/usr/sbin/gyrod --version: $(/usr/sbin/gyrod --version)"
/usr/sbin/gyrod --help | grep -q -- '--backend' || fail "gyrod --help"
/usr/bin/gyroctl --help | grep -q 'model-check' || fail "gyroctl --help"
ok "gyrod --version, gyrod --help, gyroctl --help"

# The units: ExecStart is the installed gyrod, and systemd-analyze has nothing to say about them.
grep -qx 'ExecStart=/usr/sbin/gyrod' /lib/systemd/system/gyrod.service || fail "ExecStart is not /usr/sbin/gyrod"
if command -v systemd-analyze >/dev/null 2>&1; then
  out=$(SYSTEMD_LOG_LEVEL=notice systemd-analyze verify --man=no /lib/systemd/system/gyrod.service \
    /lib/systemd/system/gyrod.socket 2>&1) || fail "systemd-analyze verify: $out"
  if printf '%s\n' "$out" | grep -E 'gyrod\.(service|socket)'; then fail "systemd-analyze verify complained"; fi
  ok "systemd-analyze verify gyrod.service gyrod.socket"
else
  echo "test-package: skipped: systemd-analyze verify (systemd-analyze not installed)"
fi
# Installing neither enables nor starts anything.
if ls /etc/systemd/system/*.wants/gyrod.* >/dev/null 2>&1; then fail "installing enabled a gyrod unit"; fi
if [ -d /run/systemd/system ] && systemctl is-active --quiet gyrod.service gyrod.socket; then
  fail "installing started gyrod"
fi
ok "gyrod.service and gyrod.socket neither enabled nor started"

# The conffile, the user and groups of sysusers.d, the udev rule, man pages, completions.
dpkg-query -W -f='${Conffiles}\n' gyrod | grep -q '^ /etc/gyrod/gyrod.toml [0-9a-f]\{32\}$' ||
  fail "/etc/gyrod/gyrod.toml is not a registered conffile"
ok "conffile: $(dpkg-query -W -f='${Conffiles}' gyrod | xargs)"
groups=$(id -nG gyrod) || fail "no gyrod user after installing"
for group in gyrod i2c gpio; do
  [[ " $groups " == *" $group "* ]] || fail "user gyrod is not in group $group (groups: $groups)"
done
ok "user gyrod in groups: $groups"
[ -f /lib/udev/rules.d/60-gyrod-devices.rules ] || fail "udev rule missing"
# `udevadm verify` exists from systemd 253 (trixie); bookworm's 252 has none.
if command -v udevadm >/dev/null 2>&1 && udevadm --help 2>/dev/null | grep -qw verify; then
  udevadm verify /lib/udev/rules.d/60-gyrod-devices.rules >/dev/null || fail "udevadm verify rejects the udev rule"
fi
for page in man8/gyrod.8 man1/gyroctl.1 man5/gyrod.toml.5; do
  file=/usr/share/man/$page.gz
  [ -f "$file" ] || fail "$file missing"
  warnings=$(zcat "$file" | LC_ALL=C.UTF-8 groff -man -Tutf8 -ww -z 2>&1) || fail "groff: $file"
  [ -z "$warnings" ] || fail "groff warns about $file: $warnings"
  if command -v man >/dev/null 2>&1; then
    MANWIDTH=80 man -l "$file" 2>/dev/null | grep -q '^NAME' || fail "man -l $file shows no NAME section"
  fi
done
ok "man pages gyrod(8), gyroctl(1), gyrod.toml(5) render without warnings"
for program in gyrod gyroctl; do
  bash -c "source /usr/share/bash-completion/completions/$program && complete -p $program" >/dev/null ||
    fail "bash completion for $program"
done
ok "bash completions load"

# gyrod from its installed path, as user gyrod, on the mock (ten times real time, so that the
# start-up bias estimate of /etc/gyrod/gyrod.toml takes 1 s), and gyroctl reading one RATE line.
run=$work_dir/run
mkdir "$run"
chown gyrod:gyrod "$run"
setpriv --reuid=gyrod --regid=gyrod --init-groups /usr/sbin/gyrod --backend mock --mock-speed 10 --socket "$run/gyrod.sock" 2>"$run/gyrod.log" &
gyrod_pid=$!
trap 'kill "$gyrod_pid" 2>/dev/null || true; rm -rf "$work_dir"' EXIT
for _ in $(seq 100); do
  [ -S "$run/gyrod.sock" ] && break
  kill -0 "$gyrod_pid" 2>/dev/null || fail "gyrod exited: $(cat "$run/gyrod.log")"
  sleep 0.1
done
line=$(timeout 30 /usr/bin/gyroctl watch --socket "$run/gyrod.sock" --json --count 1 | grep '"class":"RATE"' | head -1) ||
  fail "gyroctl watch read no RATE line; gyrod's log: $(cat "$run/gyrod.log")"
[ -n "$line" ] || fail "no RATE line"
kill -TERM "$gyrod_pid"
wait "$gyrod_pid" || fail "gyrod did not exit 0 on SIGTERM: $(cat "$run/gyrod.log")"
trap 'rm -rf "$work_dir"' EXIT
ok "gyrod (as user gyrod) on the mock, gyroctl watch: ${line:0:100}..."

# Reinstall (postinst's upgrade path): a changed conffile is kept.
echo "# changed by test-package.sh" >>/etc/gyrod/gyrod.toml
apt_get install --reinstall "./$deb" || fail "reinstalling $deb"
grep -q '^# changed by test-package.sh$' /etc/gyrod/gyrod.toml || fail "reinstalling replaced the changed conffile"
ok "reinstall keeps the changed conffile"

# Remove: the conffile stays. Then purge: nothing the package installed or made stays.
mkdir -p /var/lib/gyrod && touch /var/lib/gyrod/recording.csv /etc/gyrod/sensor.toml
dpkg -L gyrod | while read -r path; do [ -d "$path" ] || echo "$path"; done >"$run/files"
apt_get remove gyrod || fail "apt-get remove gyrod"
[ -f /etc/gyrod/gyrod.toml ] || fail "remove deleted the conffile"
apt_get purge gyrod || fail "apt-get purge gyrod"
dpkg-query -W -f='${Status}' gyrod 2>/dev/null | grep -qv 'not-installed' && fail "gyrod still known to dpkg after purge"
left=$(while read -r path; do [ ! -e "$path" ] || echo "$path"; done <"$run/files")
[ -z "$left" ] || fail "left after purge: $left"
for dir in /etc/gyrod /var/lib/gyrod /usr/share/doc/gyrod; do
  [ ! -e "$dir" ] || fail "$dir left after purge"
done
ok "remove kept the conffile; purge removed all $(wc -l <"$run/files") files, /etc/gyrod and /var/lib/gyrod"
id gyrod >/dev/null 2>&1 || fail "the gyrod user was removed (Debian keeps system users)"
ok "the gyrod user and the i2c and gpio groups stay after purge, as Debian leaves system users"

echo "test-package: passed in $(($(date +%s) - started)) s"
