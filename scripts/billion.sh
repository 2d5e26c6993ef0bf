#!/usr/bin/env bash
# The campaign of a billion points of docs/scale.md: a path campaign of N
# stations at 10 000 x 2 500, one stage per process, each timed with its
# peak resident memory (GNU time), and the project's size after each.
#   scripts/billion.sh SCANBENCH DIR N [FIRST-STAGE [LAST-STAGE]]
# Stages: simulate import geometry register merge export. DIR/stages.log
# gets a line per stage ("rc=0 Elapsed ... Maximum resident ..."); a stage
# that fails stops the run, and it can go on from that stage. Needs about
# 45 GB of disk for 48 stations (scan files 6.7 GB, project 26 GB, merged
# LAS) and /usr/bin/time (Debian package `time`).
set -u
stages="simulate import geometry register merge export"
B=$(realpath "$1"); D=$(realpath -m "$2"); N=$3; FROM=${4:-simulate}; TO=${5:-export}
for s in "$FROM" "$TO"; do
  case " $stages " in *" $s "*) ;; *) echo "billion.sh: no stage \"$s\" ($stages)" >&2; exit 2 ;; esac
done
mkdir -p "$D"; cd "$D" || exit 1
stage() {  # name, command...
  local name=$1; shift
  echo "== $name $(date +%T)" >> stages.log
  /usr/bin/time -v "$@" > "$name.out" 2> "$name.err"
  local rc=$?
  echo "rc=$rc $(grep -E 'Elapsed|Maximum resident' "$name.err" | tr -s ' ' | tr '\n' ' ')" >> stages.log
  [ $rc -eq 0 ] || exit $rc
}
go=0
for s in $stages; do
  [ "$s" = "$FROM" ] && go=1
  [ $go = 1 ] || continue
  case $s in
    simulate) stage simulate "$B" simulate --site path --scans "$N" --columns 10000 --rows 2500 \
                --pose-error-deg 3 --pose-error-m 0.5 --out "$D/sim" ;;
    import) # shellcheck disable=SC2046
            stage import "$B" import "$D/b.sbproj" $(grep '^  scan  ' simulate.out | awk '{print $NF}') ;;
    geometry) stage geometry "$B" geometry "$D/b.sbproj" ;;
    register) stage register "$B" register "$D/b.sbproj" --json ;;
    merge) stage merge "$B" merge "$D/b.sbproj" --json ;;
    export) stage export "$B" export "$D/b.sbproj" --format las --merged -o "$D/merged.las" ;;
  esac
  du -sb "$D"/b.sbproj* "$D/sim" 2>/dev/null >> stages.log
  [ "$s" = "$TO" ] && break
done
echo "== done $(date +%T)" >> stages.log
