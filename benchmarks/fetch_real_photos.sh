#!/usr/bin/env bash
# Fetch the real photos of benchmarks/vp_real.py that stay out of this repository (their
# licences) into ${CAMLOC_PHOTOS_DIR:-~/.cache/camloc_geo/photos}:
#   openMVG/SfM_quality_evaluation   Strecha 2008: 103 outdoor photos, published calibration
#   openMVG/ImageDataset_SceauxCastle 11 photos of the Chateau de Sceaux, published K, EXIF kept
#   rperrot/ReconstructionDataSet    about 530 outdoor photos of churches, doors and facades
#                                    (Canon DSLR, EXIF kept: the focal length truth), a few GB
#   erik-norlin/Structure-From-Motion the photo sets of Lund University's computer-vision course
#                                    (Kronan, a courtyard, a cathedral gate, a fountain, the Landhaus
#                                    in Graz, Heidelberg castle, ...; Nikon D60 and Coolpix 4200,
#                                    EXIF kept), about 60 MB; no licence given, so kept out
#   jeremy-shannon/CarND-Advanced-Lane-Lines  Udacity's Advanced Lane Finding frames (a dash
#                                    camera on a highway, 1280x720, 12 frames) and the 20
#                                    chessboard photos of that camera (its calibration); no
#                                    licence given, so kept out
#   Phoenix8215/FCN_KITTI            two KITTI road frames (um_000000 of training and of
#                                    testing) with their calibration files; KITTI is
#                                    non-commercial (CC BY-NC-SA 3.0), so kept out
#   open-mmlab/mmdetection3d         its demo and test data: two KITTI object frames and
#                                    the six cameras of a nuScenes sample with their
#                                    calibration (about 80 MB; KITTI and nuScenes are
#                                    non-commercial, so kept out)
#   marikhu/BrnoCompSpeed            BrnoCompSpeed (Sochor et al. 2018): one frame of each
#                                    traffic camera over a highway (sessions 0-6, left,
#                                    centre, right; 1920x1080) and the dataset's reference
#                                    calibrations (results/*/system_dubska_optimal_calib.json);
#                                    CC BY-NC-SA 4.0, so kept out; about 190 MB
#   ianare/exif-samples, drewnoakes/metadata-extractor-images, Exiv2/exiv2,
#   MikeKovarik/exifr, hMatoba/Piexif, photoprism/photoprism, h2non/bimg,
#   ethanhe42/3D-reconstruction, beauwoods/photo-portfolio, Megu09mi/megu, saryCast/grafital,
#   BrendanJohn/backbayfens
#                                    40 handheld street photos
#                                    (benchmarks/street_photos.json: compact cameras and phones,
#                                    EXIF kept), copied one by one (commit and path pinned, the
#                                    content checked against its sha256); EXIF test data of
#                                    libraries and photos of public websites, no licence
#                                    given for the photos, so kept out
#   praveenVnktsh/Panorama-Stitching, fantashi099/Panorama-Stitching,
#   jammychiou1/panorama-stitching, kyeongjin0110/Panorama-Stitching,
#   RuoyuX-2018/Panorama-Stitching, hsiaoyi0504/vfx-image-stitching, shsiung/16822hw2,
#   aayush-k/Local-Feature-Matching, Jiarui-Xu-Gatech/Camera-Calibration-and-Fundamental-
#   Matrix-Estimation-with-RANSAC, liuxianming/cs543_hw, zukun/cs543_2011,
#   polimi-ispl/prnu-python, kernelmurton/prnu, bojunyang24/CS6476
#                                    42 more (batch 8, set street-photos-held-out-2, into
#                                    street-photos-held-out-2/): course and test data, no
#                                    licence given for the photos, so kept out
#   kernelmurton/prnu, Urban-Research-Lab/building-facades-advertising-dataset,
#   jimlinntu/CS29426, yrlu/image_mosaic_stitching, sim-pez/prnu, nkisel/cs194-26-proj4,
#   f0bs/Computer_Vision, felixnie/Panoramic-Image-Stitching, muhabgadir/CS194-26,
#   shsiung/16822hw2, rohana96/ProjectiveGeometry, rushk014/image-autostitch,
#   dominathan/Photos-for-Calvin, shortstheory/cis581-3a, karahannibal/karahannibal.github.io,
#   mwomick/computational-photography
#                                    phone photos (batch 9, set street-photos-held-out-3,
#                                    into street-photos-held-out-3/): course and test data,
#                                    no licence given for the photos, so kept out
#   LycheeOrg/Lychee, albert-cwkuo/GT-CS6476-Fall2017, asethi2/CS4476, bojunyang24/CS6476,
#   drewnoakes/metadata-extractor-images, elizazhi/computational-photography,
#   jingdao/Computational-Photography, muhabgadir/CS194-26, kernelmurton/prnu,
#   Rwik2000/Panorama-Stitching, rzhu9/Computational-Photography, stevenfluo/mosaics,
#   Darfune/ORB-Image-Stitching, Derrick-M99/panorama-stitching-algorithms,
#   ImageStitching/Image-Stitching, SomeoneDistant/Panoramic-Image-Stitching,
#   cml391/computational-photography, maryamdarei/Computational-Photography,
#   seu-hrzhang/image-stitching
#                                    40 compact, DSLR and phone photos (batch 10, set
#                                    street-photos-held-out-4, into street-photos-held-out-4/):
#                                    test data, course data and SUN-database scene photos,
#                                    no licence given for the photos, so kept out
#   Kim9878/VFX-Project-1-HDR-Imaging, irisowo/HDR-Imaging, trungnguyencs/HDR-Imaging,
#   allen1759/NTU104-2_Digital-Visual-Effects, felipegb94/hdr_imaging, MercuryYen/HDR-Imaging,
#   WangJ509/vfx_hw1, s4816577/VFX_hw1_HDR, knowhow07/image_stitching,
#   kondukberna/Image_Stitching, Shimion100/autostitch, xyg-coder/panorama_stitching,
#   winswang/image_stitching, Deemsy/image_stitching, XuchenWang/Image_Stitching,
#   fantashi099/Panorama-Stitching, dominathan/Photos-for-Calvin, kernelmurton/prnu,
#   lilinwang/CS5670-Computer-Vision, Yunodoctor/TNM089-HDR-tone-mapping,
#   GiuliaBertazzini/Image-EXIF-Viewer, kevingrasso/Exif-Viewer, tomoima525/exif-extractor
#                                    34 phone, compact, DSLR and mirrorless photos (batch 11,
#                                    set street-photos-held-out-5, into
#                                    street-photos-held-out-5/): HDR, stitching and course
#                                    sets, one frame of middle brightness per exposure
#                                    bracket, no licence given for the photos, so kept out
# York Urban (research use only) is not fetched: get it from York University and set
# CAMLOC_YUD_DIR.
# Each repository is cloned from a local mirror when CAMLOC_MIRROR_DIR names one (laid out as
# owner+name/repo, a bare git directory; default /work/.mirror when it exists), else from GitHub.
# A mirror that lacks some blobs (large files left out) gives the photos it does hold (its JPEG
# files are copied out one by one, blob by blob); with none of them, GitHub is tried.
# Set CAMLOC_PHOTO_SETS to a space-separated subset of the repositories above (and
# "street-photos" for all the handheld street photos of benchmarks/street_photos.json, or
# "street-photos-held-out-2" for batch 8 alone, "street-photos-held-out-3" for batch 9 alone,
# "street-photos-held-out-4" for batch 10 alone, "street-photos-held-out-5" for batch 11 alone)
# to fetch fewer.
set -euo pipefail
dest="${CAMLOC_PHOTOS_DIR:-$HOME/.cache/camloc_geo/photos}"
default_mirror=""
[ -d /work/.mirror ] && default_mirror=/work/.mirror
mirror="${CAMLOC_MIRROR_DIR:-$default_mirror}"
sets="${CAMLOC_PHOTO_SETS:-openMVG/SfM_quality_evaluation openMVG/ImageDataset_SceauxCastle rperrot/ReconstructionDataSet erik-norlin/Structure-From-Motion jeremy-shannon/CarND-Advanced-Lane-Lines Phoenix8215/FCN_KITTI open-mmlab/mmdetection3d marikhu/BrnoCompSpeed}"
mkdir -p "$dest"

# copy_present_photos GIT_DIR DEST: the JPEG and PNG files (and small text and JSON files:
# calibrations, readmes) of HEAD whose blobs the mirror holds; prints how many photos came.
copy_present_photos() {
  local git_dir="$1" out="$2" n=0 path
  while IFS= read -r path; do
    git --git-dir="$git_dir" cat-file -e "HEAD:$path" 2>/dev/null || continue
    mkdir -p "$out/$(dirname "$path")"
    git --git-dir="$git_dir" cat-file blob "HEAD:$path" >"$out/$path"
    case "$path" in *.[jJ][pP][gG] | *.[jJ][pP][eE][gG] | *.[pP][nN][gG]) n=$((n + 1)) ;; esac
  done < <(git --git-dir="$git_dir" ls-tree -r --name-only HEAD \
    | grep -iE '\.(jpe?g|png|txt|camera|md|json)$')
  echo "$n"
}
for full in $sets; do
  [[ "$full" == */* ]] || continue # "street-photos": the single files below
  name="${full#*/}"
  if [ -d "$dest/$name" ]; then
    echo "$name: already in $dest"
    continue
  fi
  local_git="$mirror/${full%%/*}+$name/repo"
  [ -d "$local_git/.git" ] && local_git="$local_git/.git" # a mirror with a work tree
  if [ -n "$mirror" ] && [ -d "$local_git" ] && git -C "$local_git" rev-parse -q --verify HEAD >/dev/null \
    && git --git-dir="$local_git" fsck --connectivity-only HEAD >/dev/null 2>&1; then
    git clone -q "$local_git" "$dest/$name" && echo "$name: cloned from $local_git" && continue
  fi
  if [ -n "$mirror" ] && [ -d "$local_git" ]; then
    n=$(copy_present_photos "$local_git" "$dest/$name.part")
    if [ "$n" -gt 0 ]; then
      mv "$dest/$name.part" "$dest/$name"
      echo "$name: $n photos copied from $local_git (the blobs it holds)"
      continue
    fi
    rm -rf "${dest:?}/$name.part"
  fi
  git clone --depth 1 "https://github.com/$full" "$dest/$name" || {
    echo "$name: could not clone https://github.com/$full (no network?); skipped" >&2
    rm -rf "${dest:?}/$name"
  }
done

# The handheld street photos: single files of many repositories (some of them large), from
# the mirror's blobs where it holds them, else GitHub's raw files at the pinned commit.
# "street-photos" fetches every one; "street-photos-held-out-2" only batch 8 (its folder),
# "street-photos-held-out-3" only batch 9, "street-photos-held-out-4" only batch 10,
# "street-photos-held-out-5" only batch 11 (any of them, or several).
street_only=""
if [ -n "${CAMLOC_PHOTO_SETS:-}" ] && [[ " $CAMLOC_PHOTO_SETS " != *" street-photos "* ]]; then
  for s in $CAMLOC_PHOTO_SETS; do
    if [[ "$s" =~ ^street-photos-held-out-[0-9]+$ ]]; then
      street_only="${street_only:+$street_only }$s"
    fi
  done
fi
if [ -z "${CAMLOC_PHOTO_SETS:-}" ] || [ -n "$street_only" ] \
  || [[ " $CAMLOC_PHOTO_SETS " == *" street-photos "* ]]; then
  manifest="$(dirname "$0")/street_photos.json"
  got=0 failed=0
  while IFS=$'\t' read -r file repo commit path sha; do
    out="$dest/$file"
    if [ -f "$out" ] && [ "$(sha256sum "$out" | cut -d' ' -f1)" = "$sha" ]; then
      got=$((got + 1))
      continue
    fi
    mkdir -p "$(dirname "$out")"
    git_dir="$mirror/${repo%%/*}+${repo#*/}/repo"
    [ -d "$git_dir/.git" ] && git_dir="$git_dir/.git"
    if ! { [ -n "$mirror" ] && git --git-dir="$git_dir" cat-file blob "$commit:$path" >"$out" 2>/dev/null; }; then
      curl -fsSL "https://raw.githubusercontent.com/$repo/$commit/${path// /%20}" -o "$out" || true
    fi
    if [ -f "$out" ] && [ "$(sha256sum "$out" | cut -d' ' -f1)" = "$sha" ]; then
      got=$((got + 1))
    else
      rm -f "$out"
      failed=$((failed + 1))
    fi
  done < <(python3 -c 'import json, sys
only = sys.argv[2].split()
for p in json.load(open(sys.argv[1]))["photos"]:
    if only and not any(p["file"].startswith(f + "/") for f in only):
        continue
    print("\t".join((p["file"], p["repo"], p["commit"], p["path"], p["sha256"])))' \
    "$manifest" "$street_only")
  echo "street-photos: $got photos in $dest (street-photos/, street-photos-held-out-2/ ... street-photos-held-out-5/)"
  [ "$failed" -eq 0 ] || echo "street-photos: $failed not fetched (no mirror, no network?)" >&2
fi
echo "photos in $dest; run: python benchmarks/vp_real.py"
