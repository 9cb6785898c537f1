#!/usr/bin/env bash
# Fetch the real photos of benchmarks/vp_real.py that stay out of this repository (their
# licences): openMVG's public Strecha 2008 and Sceaux castle sets, into
# ${CAMLOC_PHOTOS_DIR:-~/.cache/camloc_geo/photos}. York Urban (research use only) is not
# fetched: get it from York University and set CAMLOC_YUD_DIR.
set -euo pipefail
dest="${CAMLOC_PHOTOS_DIR:-$HOME/.cache/camloc_geo/photos}"
mkdir -p "$dest"
for repo in SfM_quality_evaluation ImageDataset_SceauxCastle; do
  if [ ! -d "$dest/$repo" ]; then
    git clone --depth 1 "https://github.com/openMVG/$repo" "$dest/$repo"
  fi
done
echo "photos in $dest; run: python benchmarks/vp_real.py"
