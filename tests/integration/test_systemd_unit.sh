#!/bin/sh
# The shipped unit passes systemd-analyze verify and keeps its offline exposure score "OK" or
# better. verify checks that ExecStart exists, so it runs on a copy pointing at the built hsad.
# unit_src is the unit as the build configured it (build/systemd/hsad.service).
set -eu
unit_src="$1"
hsad="$2"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
sed "s|^ExecStart=[^ ]*/hsad |ExecStart=$hsad |" "$unit_src" > "$dir/hsad.service"
grep -q "^ExecStart=$hsad " "$dir/hsad.service" || { echo "no ExecStart=.../hsad in $unit_src"; exit 1; }
out=$(systemd-analyze verify "$dir/hsad.service" 2>&1) || { echo "$out"; exit 1; }
if [ -n "$out" ]; then echo "systemd-analyze verify complained:"; echo "$out"; exit 1; fi
score=$(systemd-analyze security --offline=true "$dir/hsad.service" | sed -n 's/.*Overall exposure level for hsad.service: \([0-9.]*\) \([A-Z]*\).*/\1 \2/p')
echo "exposure: $score"
case "$score" in
  *" OK"|*" SAFE") exit 0 ;;
  *) echo "exposure level worse than OK"; exit 1 ;;
esac
