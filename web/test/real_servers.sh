#!/usr/bin/env bash
# The web client against real static web servers (called by web/test/run.sh):
#   bash web/test/real_servers.sh FILE.pomar
# serves FILE.pomar with Debian's nginx and Apache (each on a free local port, from a
# throw-away configuration in a temporary folder: no system service is touched) and runs
# web/test/server_check.mjs against each: the same meshes as from the local file, the
# file fetched exactly once, several ranges per request (both answer multipart/byteranges).
# A server that is not installed is skipped with a message (scripts/setup.sh installs both).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
FILE="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
work="$(mktemp -d)"
chmod 755 "$work" # the servers' workers (another user) read the file
mkdir -p "$work/www" "$work/tmp"
cp "$FILE" "$work/www/model.pomar"
chmod 644 "$work/www/model.pomar"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# Wait until the server answers on its port (at most 10 s); 1 if it never does.
wait_for() {
  for _ in $(seq 100); do
    if python3 -c "import socket,sys; socket.create_connection(('127.0.0.1', $1), 0.2)" 2>/dev/null; then
      return 0
    fi
    sleep 0.1
  done
  return 1
}

check() { # NAME PORT LOG
  echo "real servers: $1 (node web/test/server_check.mjs)"
  if ! wait_for "$2"; then
    echo "real servers: $1 did not start:" >&2
    cat "$3" >&2 || true
    exit 1
  fi
  EXPECT_MULTIPART=1 node "$REPO/web/test/server_check.mjs" "http://127.0.0.1:$2/model.pomar" "$FILE"
}

if command -v nginx >/dev/null 2>&1 || [ -x /usr/sbin/nginx ]; then
  nginx_bin="$(command -v nginx || echo /usr/sbin/nginx)"
  port="$(free_port)"
  user_line=""
  [ "$(id -u)" = 0 ] && user_line="user root;" # (as root the workers would be nobody)
  cat >"$work/nginx.conf" <<EOF
$user_line
daemon off;
worker_processes 1;
pid $work/nginx.pid;
error_log $work/nginx_error.log;
events {}
http {
  access_log $work/nginx_access.log;
  client_body_temp_path $work/tmp;
  types { application/octet-stream pomar; }
  server {
    listen 127.0.0.1:$port;
    root $work/www;
  }
}
EOF
  "$nginx_bin" -p "$work" -c "$work/nginx.conf" 2>>"$work/nginx_error.log" &
  pids+=($!)
  check "nginx $("$nginx_bin" -v 2>&1 | sed 's/.*nginx\///')" "$port" "$work/nginx_error.log"
else
  echo "real servers: nginx SKIPPED: not installed (scripts/setup.sh installs nginx-light)"
fi

if [ -x /usr/sbin/apache2 ]; then
  port="$(free_port)"
  modules=/usr/lib/apache2/modules
  cat >"$work/apache2.conf" <<EOF
ServerRoot $work
ServerName localhost
Listen 127.0.0.1:$port
PidFile $work/apache2.pid
DefaultRuntimeDir $work/tmp
ErrorLog $work/apache2_error.log
LoadModule mpm_event_module $modules/mod_mpm_event.so
LoadModule authz_core_module $modules/mod_authz_core.so
DocumentRoot $work/www
<Directory $work/www>
  Require all granted
</Directory>
EOF
  [ "$(id -u)" = 0 ] && printf 'User nobody\nGroup nogroup\n' >>"$work/apache2.conf"
  /usr/sbin/apache2 -f "$work/apache2.conf" -DFOREGROUND 2>>"$work/apache2_error.log" &
  pids+=($!)
  check "Apache $(/usr/sbin/apache2 -v | sed -n 's/^Server version: Apache\/\([^ ]*\).*/\1/p')" "$port" \
    "$work/apache2_error.log"
else
  echo "real servers: Apache SKIPPED: not installed (scripts/setup.sh installs apache2)"
fi
