#!/usr/bin/env bash
# Fetch the real photos of benchmarks/vp_real.py that stay out of this repository (their
# licences) into ${CAMLOC_PHOTOS_DIR:-~/.cache/camloc_geo/photos}:
#   openMVG/SfM_quality_evaluation   Strecha 2008: 103 outdoor photos, published calibration
#   openMVG/ImageDataset_SceauxCastle 11 photos of the Chateau de Sceaux, published K, EXIF kept
#   rperrot/ReconstructionDataSet    about 530 outdoor photos of churches, doors and facades
#                                    (Canon DSLR, EXIF kept: the focal length truth), a few GB
# York Urban (research use only) is not fetched: get it from York University and set
# CAMLOC_YUD_DIR.
# Each repository is cloned from a local mirror when CAMLOC_MIRROR_DIR names one (laid out as
# owner+name/repo, a bare git directory), else from GitHub.
# A mirror that lacks the photo blobs (large files left out) is skipped for GitHub.
# Set CAMLOC_PHOTO_SETS to a space-separated subset of the repositories above to fetch fewer.
set -euo pipefail
dest="${CAMLOC_PHOTOS_DIR:-$HOME/.cache/camloc_geo/photos}"
mirror="${CAMLOC_MIRROR_DIR:-}"
sets="${CAMLOC_PHOTO_SETS:-openMVG/SfM_quality_evaluation openMVG/ImageDataset_SceauxCastle rperrot/ReconstructionDataSet}"
mkdir -p "$dest"
for full in $sets; do
  name="${full#*/}"
  if [ -d "$dest/$name" ]; then
    echo "$name: already in $dest"
    continue
  fi
  local_git="$mirror/${full%%/*}+$name/repo"
  if [ -n "$mirror" ] && [ -d "$local_git" ] && git -C "$local_git" rev-parse -q --verify HEAD >/dev/null \
    && git --git-dir="$local_git" fsck --connectivity-only HEAD >/dev/null 2>&1; then
    git clone -q "$local_git" "$dest/$name" && echo "$name: cloned from $local_git" && continue
  fi
  git clone --depth 1 "https://github.com/$full" "$dest/$name" || {
    echo "$name: could not clone https://github.com/$full (no network?); skipped" >&2
    rm -rf "${dest:?}/$name"
  }
done
echo "photos in $dest; run: python benchmarks/vp_real.py"
