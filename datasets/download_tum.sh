#!/usr/bin/env bash
# Downloads TUM RGB-D benchmark sequences (Sturm et al., IROS 2012; CC BY 4.0) by name, checks and
# unpacks them. Not run in CI (the tests use ../shared/data).
#
#   datasets/download_tum.sh freiburg1_desk freiburg1_xyz [--dir DIR]
#
# A NAME is the sequence name without the "rgbd_dataset_" prefix (freiburg1_desk, fr1/desk and
# rgbd_dataset_freiburg1_desk are all accepted). The folder lands in DIR (default: datasets/tum),
# ready for:  seamless run configs/tum_fr1.yaml --set input.path=DIR/rgbd_dataset_freiburg1_desk
set -euo pipefail

BASE_URL="https://cvg.cit.tum.de/rgbd/dataset"
DIR="$(cd "$(dirname "$0")" && pwd)/tum"
names=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --dir) DIR="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) names+=("$1"); shift ;;
  esac
done
if [[ ${#names[@]} -eq 0 ]]; then
  echo "usage: $0 NAME... [--dir DIR]   e.g. $0 freiburg1_desk freiburg2_xyz" >&2
  exit 2
fi
command -v tar >/dev/null || { echo "error: tar is required" >&2; exit 1; }
if command -v curl >/dev/null; then fetch() { curl -fL --retry 3 -o "$2" "$1"; }
elif command -v wget >/dev/null; then fetch() { wget -O "$2" "$1"; }
else echo "error: curl or wget is required (apt-get install curl)" >&2; exit 1; fi

mkdir -p "$DIR"
for raw in "${names[@]}"; do
  name="${raw#rgbd_dataset_}"
  name="${name/fr1\//freiburg1_}"; name="${name/fr2\//freiburg2_}"; name="${name/fr3\//freiburg3_}"
  if [[ ! "$name" =~ ^freiburg[123]_[a-z0-9_]+$ ]]; then
    echo "error: '$raw' is not a TUM sequence name (expected e.g. freiburg1_desk)" >&2
    exit 2
  fi
  seq="rgbd_dataset_${name}"
  if [[ -f "$DIR/$seq/associations.txt" || -f "$DIR/$seq/rgb.txt" ]]; then
    echo "$seq: already in $DIR"
    continue
  fi
  fb="${name%%_*}"                       # freiburg1
  url="$BASE_URL/$fb/$seq.tgz"
  tgz="$DIR/$seq.tgz"
  echo "$seq: downloading $url"
  fetch "$url" "$tgz.part" || { echo "error: download of $url failed (name misspelt? see the TUM list)" >&2; rm -f "$tgz.part"; exit 1; }
  mv "$tgz.part" "$tgz"
  # Check: a complete gzip'd tar whose top folder is the sequence with its list files.
  if ! tar -tzf "$tgz" > "$DIR/$seq.list" 2>/dev/null; then
    echo "error: $tgz is truncated or not a tar.gz; delete it and retry" >&2
    exit 1
  fi
  for f in rgb.txt depth.txt; do
    grep -q "^$seq/$f\$" "$DIR/$seq.list" || { echo "error: $tgz has no $seq/$f" >&2; exit 1; }
  done
  tar -xzf "$tgz" -C "$DIR"
  rm -f "$tgz" "$DIR/$seq.list"
  n_rgb=$(grep -vc '^#' "$DIR/$seq/rgb.txt" || true)
  n_png=$(find "$DIR/$seq/rgb" -name '*.png' | wc -l)
  if [[ "$n_rgb" != "$n_png" ]]; then
    echo "error: $seq lists $n_rgb colour images but has $n_png" >&2
    exit 1
  fi
  echo "$seq: $n_png frames in $DIR/$seq (pairs made at load time like associate.py, or run it yourself)"
done
