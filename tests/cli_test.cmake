# tests/cli_test.cmake — the clvr program end to end (cmake -P): exit codes, one-line errors that name
# the file, valid outputs, and no output file after any failure (DESIGN.md, "Scene files and the command
# line"). Inputs: CLVR (the program), SRC (source tree), WORK (scratch folder), PART (basics, input, device
# or frames: the part of the checks to run; tests/CMakeLists.txt makes each part its own CTest test,
# cli.PART, so that ctest -j runs them side by side). Images are 64x64 to stay fast.
if(NOT PART MATCHES "^(basics|input|device|frames)$")
  message(FATAL_ERROR "PART \"${PART}\": want basics, input, device or frames")
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(SMALL --set image.width=64 --set image.height=64)
set(out "${WORK}/out.png")

function(expect_run expected_rc pattern)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT rc STREQUAL "${expected_rc}")
    message(FATAL_ERROR "${ARGN}\n  exit ${rc}, want ${expected_rc}\n  stdout: ${out}\n  stderr: ${err}")
  endif()
  if(NOT "${out}${err}" MATCHES "${pattern}")
    message(FATAL_ERROR "${ARGN}\n  output does not match '${pattern}'\n  stdout: ${out}\n  stderr: ${err}")
  endif()
endfunction()

# expect_error(RC OUTPUT PATTERN args...): exit RC, nothing on stdout, exactly one stderr line
# "clvr: error: ..." that contains PATTERN (a regex: the file's name and what is wrong), and no OUTPUT file.
function(expect_error expected_rc output pattern)
  file(REMOVE "${output}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  set(context "${ARGN}\n  exit ${rc}\n  stdout: ${out}\n  stderr: ${err}")
  if(NOT rc STREQUAL "${expected_rc}")
    message(FATAL_ERROR "${context}\n  want exit ${expected_rc}")
  endif()
  if(NOT out STREQUAL "")
    message(FATAL_ERROR "${context}\n  want nothing on stdout")
  endif()
  if(NOT err MATCHES "^clvr: error: [^\n]*\n$")
    message(FATAL_ERROR "${context}\n  want exactly one line 'clvr: error: ...' on stderr")
  endif()
  if(NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "${context}\n  stderr does not match '${pattern}'")
  endif()
  if(EXISTS "${output}")
    message(FATAL_ERROR "${context}\n  left an output file ${output}")
  endif()
  file(GLOB leftovers "${WORK}/.*.tmp*")
  if(leftovers)
    message(FATAL_ERROR "${context}\n  left temporary files: ${leftovers}")
  endif()
endfunction()

# The width and height in a PNG's IHDR chunk (bytes 16..23, big-endian), after checking its signature.
function(expect_png path want_w want_h)
  if(NOT EXISTS "${path}")
    message(FATAL_ERROR "${path} was not written")
  endif()
  file(READ "${path}" head LIMIT 24 HEX)
  string(SUBSTRING "${head}" 0 16 signature)
  if(NOT signature STREQUAL "89504e470d0a1a0a")
    message(FATAL_ERROR "${path} is not a PNG (starts with ${signature})")
  endif()
  string(SUBSTRING "${head}" 32 8 w)
  string(SUBSTRING "${head}" 40 8 h)
  math(EXPR w "0x${w}")
  math(EXPR h "0x${h}")
  if(NOT w EQUAL want_w OR NOT h EQUAL want_h)
    message(FATAL_ERROR "${path} is ${w}x${h}, want ${want_w}x${want_h}")
  endif()
endfunction()

# A clip mesh and a mesh surface in TetGen's formats (read by clvr; TetGen's own readers would print
# "Opening FILE." on stdout): clvr's stdout is its own one line.
function(expect_one_stdout_line scene)
  execute_process(COMMAND ${CLVR} render ${SRC}/data/scenes/${scene}.json -o ${WORK}/${scene}.png ${SMALL} ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "^wrote [^\n]*\n$")
    message(FATAL_ERROR "clvr render ${scene}: exit ${rc}, want 0 and one line 'wrote ...' on stdout\n  stdout: ${out}\n  stderr: ${err}")
  endif()
endfunction()

if(PART STREQUAL "basics")
  # --- usage and devices
  expect_run(0 "using device" ${CLVR} info)
  expect_run(0 "--output" ${CLVR} render --help)
  expect_run(0 "render" ${CLVR} --help)
  expect_error(2 "${WORK}/none.png" "command line: .*no-such-command" ${CLVR} no-such-command)
  expect_error(2 "${WORK}/none.png" "command line: .*--output" ${CLVR} render)
  expect_run(3 "^clvr: error: .*matches no OpenCL device" ${CLVR} info --device no-such-device-xyz)

  # --- good renders: the default scene (omitted and named), PNG of the right size, EXR, stats with every key
  set(png "${WORK}/default.png")
  expect_run(0 "^wrote .*default.png \\(64x64, slice3d, [0-9.]+ ms/frame\\)\n$"
    ${CLVR} render -o ${png} ${SMALL} --stats ${WORK}/stats.json)
  expect_png(${png} 64 64)
  file(READ "${WORK}/stats.json" stats)
  foreach(key technique device width height frame_ms compile_ms first_frame_ms passes voxels samples resident_bytes
      host_peak_bytes device_bytes device_peak_bytes)
    string(JSON value ERROR_VARIABLE missing GET "${stats}" ${key})
    if(missing)
      message(FATAL_ERROR "stats.json has no \"${key}\":\n${stats}")
    endif()
  endforeach()
  string(JSON width GET "${stats}" width)
  string(JSON technique GET "${stats}" technique)
  string(JSON npasses LENGTH "${stats}" passes)
  string(JSON pass0 GET "${stats}" passes 0 name)
  if(NOT width EQUAL 64 OR NOT technique STREQUAL "slice3d" OR npasses LESS 1 OR pass0 STREQUAL "")
    message(FATAL_ERROR "stats.json: unexpected values:\n${stats}")
  endif()
  expect_run(0 "wrote .*named.png \\(48x32," ${CLVR} render default -o ${WORK}/named.png
    --set image.width=48 --set image.height=32)
  expect_png(${WORK}/named.png 48 32)
  expect_run(0 "wrote .*default.exr" ${CLVR} render -o ${WORK}/default.exr ${SMALL})
  file(READ "${WORK}/default.exr" exrMagic LIMIT 4 HEX)
  if(NOT exrMagic STREQUAL "762f3101")
    message(FATAL_ERROR "default.exr is not an OpenEXR file (starts with ${exrMagic})")
  endif()

  # A scene file with a relative data path and no camera (the camera fits the bounds); a NRRD written here.
  file(WRITE "${WORK}/data/cube.nrrd" "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: ascii\n\n")
  foreach(i RANGE 63)
    math(EXPR v "(${i} * 4) % 256")
    file(APPEND "${WORK}/data/cube.nrrd" "${v}\n")
  endforeach()
  file(WRITE "${WORK}/cube.json" [=[{
    "volume": {"file": "data/cube.nrrd"},
    "image": {"width": 40, "height": 30},
    "transfer_function": {"points": [[0, 0,0,0, 0], [255, 1,1,1, 0.5]]}
  }]=])
  expect_run(0 "wrote .*cube.png \\(40x30, slice3d" ${CLVR} render ${WORK}/cube.json -o ${WORK}/cube.png)
  expect_png(${WORK}/cube.png 40 30)

  # --- clvr techniques: every technique with its data kind and options, defaults and one line each
  expect_run(0 "slice3d \\(volume\\): [^\n]+\n  slices +256 +view-aligned" ${CLVR} techniques)
  expect_run(0 "\nharc \\(mesh\\): [^\n]+\n.*  max_layers +64 " ${CLVR} techniques)
  expect_run(0 "^planes \\(volume\\): [^\n]+\n  sample_spacing +\\(half the smallest grid spacing\\)" ${CLVR} techniques planes)
  expect_error(2 "${WORK}/none.png" "technique: unknown technique \"slice4d\" \\(known: slice3d, " ${CLVR} techniques slice4d)

  # --- --unset: a key removed before validation; the default scene's options are the defaults, its camera
  # is not the fitted one; a key that is not there is an error naming it
  expect_run(0 "wrote" ${CLVR} render -o ${WORK}/unset-none.png ${SMALL})
  expect_run(0 "wrote" ${CLVR} render -o ${WORK}/unset-options.png ${SMALL} --unset options)
  expect_run(0 "wrote" ${CLVR} render -o ${WORK}/unset-camera.png ${SMALL} --unset camera)
  file(SHA256 "${WORK}/unset-none.png" hashNone)
  file(SHA256 "${WORK}/unset-options.png" hashOptions)
  file(SHA256 "${WORK}/unset-camera.png" hashCamera)
  if(NOT hashOptions STREQUAL hashNone)
    message(FATAL_ERROR "--unset options (the default slices: 256) differs from the default scene's {\"slices\": 256}")
  endif()
  if(hashCamera STREQUAL hashNone)
    message(FATAL_ERROR "--unset camera (the fitted camera) gives the scene camera's image")
  endif()
  expect_error(2 "${WORK}/none.png" "default scene: --unset \"camera.fov\": the scene has no key \"camera.fov\""
    ${CLVR} render -o ${WORK}/none.png ${SMALL} --unset camera.fov)
  expect_run(0 "--unset" ${CLVR} bench --help)
endif()

if(PART STREQUAL "input")
  # --- bad input: exit 2, one line naming the file, no output file
  expect_error(2 ${out} "missing.json: no such scene file" ${CLVR} render ${WORK}/missing.json -o ${out})
  file(WRITE "${WORK}/malformed.json" "{\n  \"volume\": {\"generator\": \"sphere\" \"dims\": [8,8,8]}\n}\n")
  expect_error(2 ${out} "malformed.json: malformed JSON at line 2, column" ${CLVR} render ${WORK}/malformed.json -o ${out})
  file(WRITE "${WORK}/truncated.json" "{\n  \"volume\": {\"generator\": \"sphere\",")
  expect_error(2 ${out} "truncated.json: malformed JSON at line 2" ${CLVR} render ${WORK}/truncated.json -o ${out})
  file(WRITE "${WORK}/unknown.json" [=[{
    "volume": {"generator": "sphere", "dims": [8,8,8]},
    "camera": {"position": [0,0,4], "fov": 30},
    "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}
  }]=])
  expect_error(2 ${out} "unknown.json: unknown key \"camera.fov\" \\(known: position," ${CLVR} render ${WORK}/unknown.json -o ${out})
  expect_error(2 ${out} "default scene: --set \"camera.position=\\[0,0,\": malformed value"
    ${CLVR} render -o ${out} --set "camera.position=[0,0,")
  expect_error(2 ${out} "default scene: --set \"camera\": expected path=value" ${CLVR} render -o ${out} --set camera)
  expect_error(2 "${WORK}/out.jpg" "out.jpg: unsupported image format \"\\.jpg\"" ${CLVR} render -o ${WORK}/out.jpg ${SMALL})
  expect_error(2 "${WORK}/no-dir/out.png" "no-dir/out.png: directory .*no-dir does not exist"
    ${CLVR} render -o ${WORK}/no-dir/out.png ${SMALL})
  expect_error(2 ${out} "default scene: image.width must be in 1..16384, got 0" ${CLVR} render -o ${out} --set image.width=0)
  # slice3d clip meshes (docs/slice3d.md): a bad key, a missing file, an open surface.
  expect_error(2 ${out} "options.clip.mesh.generator: must be \"box\", \"sphere\" or \"cylinder\""
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip={\"mesh\": {\"generator\": \"cone\"}}")
  expect_error(2 ${out} "no-such-mesh.off: no such file \\(clip mesh\\)"
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip={\"mesh\": \"${WORK}/no-such-mesh.off\"}")
  file(WRITE "${WORK}/open.obj" "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n")
  expect_error(2 ${out} "open.obj: the clip mesh is not a closed, consistently oriented surface"
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip={\"mesh\": \"${WORK}/open.obj\"}")
  # slice3d clip textures (docs/slice3d.md): a bad shape, a negative radius, a missing mask; one renders.
  expect_error(2 ${out} "options.clip_texture.shape: must be \"sphere\", \"box\" or \"cylinder\", got \"torus\""
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip_texture={\"shape\": \"torus\"}")
  expect_error(2 ${out} "options.clip_texture.radius: must be a positive number, got -1"
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip_texture={\"shape\": \"sphere\", \"radius\": -1}")
  expect_error(2 ${out} "no-such-mask.nrrd: no such file \\(clip texture mask\\)"
    ${CLVR} render -o ${out} ${SMALL} --set "options.clip_texture={\"mask\": \"${WORK}/no-such-mask.nrrd\"}")
  expect_run(0 "wrote .*clipped.png \\(64x64, slice3d," ${CLVR} render -o ${WORK}/clipped.png ${SMALL}
    --set "options.clip_texture={\"shape\": \"box\", \"inverse\": true}")
  expect_png(${WORK}/clipped.png 64 64)
  expect_error(2 ${out} "default scene: technique: unknown technique \"no-such-technique\"" ${CLVR} render -o ${out} ${SMALL} --set technique=no-such-technique)
  file(WRITE "${WORK}/nodata.json" [=[{
    "volume": {"file": "data/not-there.nrrd"},
    "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}
  }]=])
  expect_error(2 ${out} "data/not-there.nrrd: no such file" ${CLVR} render ${WORK}/nodata.json -o ${out} ${SMALL})
  # A NRRD whose header promises 8x8x8 uint16 samples (1024 bytes) but carries 100.
  string(REPEAT "x" 100 shortData)
  file(WRITE "${WORK}/data/short.nrrd" "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 8 8 8\nendian: little\nencoding: raw\n\n${shortData}")
  file(WRITE "${WORK}/short.json" [=[{
    "volume": {"file": "data/short.nrrd"},
    "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}
  }]=])
  expect_error(2 ${out} "data/short.nrrd: header says 8x8x8" ${CLVR} render ${WORK}/short.json -o ${out} ${SMALL})
  file(WRITE "${WORK}/nan.json" [=[{
    "volume": {"generator": "sphere", "dims": [8,8,8]},
    "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 1e999]]}
  }]=])
  expect_error(2 ${out} "nan.json: malformed JSON at line 3, column [0-9]+: number 1e999 is out of range"
    ${CLVR} render ${WORK}/nan.json -o ${out} ${SMALL})
  expect_error(2 ${out} "default scene: transfer_function.points\\[1\\]\\[1\\] must be a number"
    ${CLVR} render -o ${out} ${SMALL} "--set=transfer_function.points=[[0,0,0,0,0],[1,\"nan\",1,1,1]]")
  expect_error(2 ${out} "stats.json: directory .*no-dir does not exist"
    ${CLVR} render -o ${out} ${SMALL} --stats ${WORK}/no-dir/stats.json)

  expect_error(2 ${out} "default scene: options.slicez: unknown option"
    ${CLVR} render -o ${out} ${SMALL} --set options.slicez=3)

  # --- VTK's formats (host/io/vtk_xml_io.h): a .vti and a .pvti of one piece render; a missing piece, a
  # broken file and cell data are one line each; a build without VTK says so in one line.
  set(vti_data "0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26")
  file(WRITE "${WORK}/cube.vti" "<?xml version=\"1.0\"?>
<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">
  <ImageData WholeExtent=\"0 2 0 2 0 2\" Origin=\"-1 -1 -1\" Spacing=\"1 1 1\">
  <Piece Extent=\"0 2 0 2 0 2\">
    <PointData Scalars=\"s\"><DataArray type=\"UInt8\" Name=\"s\" format=\"ascii\">${vti_data}</DataArray></PointData>
  </Piece>
  </ImageData>
</VTKFile>
")
  file(WRITE "${WORK}/cube.pvti" "<?xml version=\"1.0\"?>
<VTKFile type=\"PImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">
  <PImageData WholeExtent=\"0 2 0 2 0 2\" GhostLevel=\"0\" Origin=\"-1 -1 -1\" Spacing=\"1 1 1\">
    <PPointData Scalars=\"s\"><PDataArray type=\"UInt8\" Name=\"s\"/></PPointData>
    <Piece Extent=\"0 2 0 2 0 2\" Source=\"cube.vti\"/>
  </PImageData>
</VTKFile>
")
  file(READ "${WORK}/cube.pvti" pvti)
  string(REPLACE "cube.vti" "gone.vti" pvti "${pvti}")
  file(WRITE "${WORK}/gone.pvti" "${pvti}")
  file(READ "${WORK}/cube.vti" vti)
  string(REPLACE "PointData" "CellData" cells "${vti}")
  file(WRITE "${WORK}/cells.vti" "${cells}")
  string(SUBSTRING "${vti}" 0 200 broken)
  file(WRITE "${WORK}/broken.vti" "${broken}")
  set(TF "--set=transfer_function.points=[[0,0,0,0,0],[26,1,1,1,4]]")
  if(VTK)
    foreach(name cube.vti cube.pvti)
      expect_run(0 "^wrote .*cube.png" ${CLVR} render -o ${WORK}/cube.png ${SMALL} ${TF}
        "--set=volume={\"file\": \"${WORK}/${name}\"}" --unset camera)
      expect_png(${WORK}/cube.png 64 64)
    endforeach()
    expect_error(2 ${out} "gone.pvti: its piece gone.vti cannot be read"
      ${CLVR} render -o ${out} ${SMALL} ${TF} "--set=volume={\"file\": \"${WORK}/gone.pvti\"}" --unset camera)
    expect_error(2 ${out} "cells.vti: no point data, only cell data \\(s\\)"
      ${CLVR} render -o ${out} ${SMALL} ${TF} "--set=volume={\"file\": \"${WORK}/cells.vti\"}" --unset camera)
    expect_error(2 ${out} "broken.vti: VTK's reader failed: "
      ${CLVR} render -o ${out} ${SMALL} ${TF} "--set=volume={\"file\": \"${WORK}/broken.vti\"}" --unset camera)
  else()
    expect_error(2 ${out} "cube.vti: this clvr was built without VTK"
      ${CLVR} render -o ${out} ${SMALL} ${TF} "--set=volume={\"file\": \"${WORK}/cube.vti\"}" --unset camera)
  endif()
endif()

if(PART STREQUAL "device")
  # --- device failures: exit 3, one line, no output file
  expect_error(3 ${out} "--device \"no-such-device\" matches no OpenCL device"
    ${CLVR} render -o ${out} ${SMALL} --device no-such-device)
  # No OpenCL platform at all: the ICD loader finds no vendor file in an empty folder.
  file(MAKE_DIRECTORY "${WORK}/empty-icd")
  expect_error(3 ${out} "no OpenCL device"
    ${CMAKE_COMMAND} -E env OCL_ICD_VENDORS=${WORK}/empty-icd ${CLVR} render -o ${out} ${SMALL})
  # Beyond one allocation: CLVR_DEVICE_MEMORY_LIMIT makes the device report 1 MiB, less than the default
  # scene's 128^3 float volume (8 MiB): slice3d renders it in bricks (host/cluster/bricks.h), the image of
  # the whole volume within 1/255; a technique that cannot render parts gets one line naming what did not fit.
  expect_run(0 "wrote" ${CMAKE_COMMAND} -E env CLVR_DEVICE_MEMORY_LIMIT=1M ${CLVR} render -o ${WORK}/bricked.png
    ${SMALL} --stats ${WORK}/bricked-parts.json)
  file(READ ${WORK}/bricked-parts.json parts_stats)
  string(JSON parts GET "${parts_stats}" volume_parts)
  if(parts LESS 8)
    message(FATAL_ERROR "the 8 MiB volume on a 1 MiB device in ${parts} parts, want at least 8")
  endif()
  expect_run(0 "wrote" ${CLVR} render -o ${WORK}/unbricked.png ${SMALL})
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/bricked.png ${WORK}/unbricked.png RESULT_VARIABLE same)
  find_program(OIIOTOOL oiiotool)
  if(NOT same EQUAL 0 AND OIIOTOOL)
    execute_process(COMMAND ${OIIOTOOL} ${WORK}/bricked.png ${WORK}/unbricked.png --fail 0.004 --diff
      RESULT_VARIABLE rc OUTPUT_VARIABLE diff)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "bricked and whole images differ by more than 1/255:\n${diff}")
    endif()
  endif()
  expect_error(3 ${out} "out of device memory: texture needs 8 MiB"
    ${CMAKE_COMMAND} -E env CLVR_DEVICE_MEMORY_LIMIT=1M ${CLVR} render -o ${out} ${SMALL} --set technique=spherical
    --unset options)
  # Bricking (iso3d, §3.1 of seeds/000, docs/iso3d.md): on the same 1 MiB device the 64^3 volume's RGBA texture
  # (4 MiB) does not fit whole, but cut into bricks of at most 512 KiB it renders; a budget below the smallest
  # brick is bad input.
  set(ISO --set technique=iso3d --set "iso={\"value\":0.5}" --set "volume.dims=[64,64,64]")
  expect_error(3 ${out} "out of device memory: .*iso3d RGBA volume.*needs 4 MiB"
    ${CMAKE_COMMAND} -E env CLVR_DEVICE_MEMORY_LIMIT=1M ${CLVR} render -o ${out} ${SMALL} ${ISO} --set options.slices=64)
  expect_run(0 "wrote" ${CMAKE_COMMAND} -E env CLVR_DEVICE_MEMORY_LIMIT=1M ${CLVR} render -o ${out} ${SMALL} ${ISO}
    --set options.slices=64 --set options.brick_budget=524288 --stats ${WORK}/bricked-stats.json)
  expect_png(${out} 64 64)
  file(READ ${WORK}/bricked-stats.json bricked_stats)
  if(NOT bricked_stats MATCHES "\"bricks\": *(1[0-9]|[2-9][0-9])[^0-9]")
    message(FATAL_ERROR "bricked render: want 10..99 bricks in --stats, got ${bricked_stats}")
  endif()
  expect_error(2 ${out} "default scene: options.brick_budget: 100 bytes is less than the smallest brick"
    ${CLVR} render -o ${out} ${SMALL} ${ISO} --set options.brick_budget=100)
  # Faults injected mid-run (CLVR_INJECT_FAULT, docs/robustness.md): a launch in the middle of an iso3d frame
  # (the 2nd, its shading pass: the fused slices come before it) and of an orbit's last frame (the 5th: frame 0 renders
  # twice) fail with exit 3 and one line, and leave no image (the orbit's first frames are removed again);
  # a kernel build failure exits 3 with the compiler's log under the line; a malformed value is bad input.
  expect_error(3 ${out} "launching \"[^\"]+\" failed: CL_OUT_OF_RESOURCES \\(injected by CLVR_INJECT_FAULT=launch:2\\)"
    ${CMAKE_COMMAND} -E env CLVR_INJECT_FAULT=launch:2 ${CLVR} render -o ${out} ${SMALL} ${ISO} --stats ${WORK}/fault.json)
  if(EXISTS ${WORK}/fault.json)
    message(FATAL_ERROR "a failed launch left its --stats file")
  endif()
  file(MAKE_DIRECTORY "${WORK}/fault-frames")
  expect_error(3 "${WORK}/fault-frames/f0.png" "injected by CLVR_INJECT_FAULT=launch:5"
    ${CMAKE_COMMAND} -E env CLVR_INJECT_FAULT=launch:5 ${CLVR} render -o "${WORK}/fault-frames/f%d.png" ${SMALL} --orbit 4)
  file(GLOB written "${WORK}/fault-frames/*")
  if(written)
    message(FATAL_ERROR "an --orbit whose last frame failed left files: ${written}")
  endif()
  file(REMOVE ${out})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env CLVR_INJECT_FAULT=build ${CLVR} render -o ${out} ${SMALL}
    RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr TIMEOUT 300)
  if(NOT rc EQUAL 3 OR NOT stderr MATCHES "clvr: error: building kernels/[a-z0-9_]+\\.cl for [^\n]+ failed: CL_BUILD_PROGRAM_FAILURE\n"
     OR NOT stderr MATCHES "CLVR_INJECT_FAULT=build" OR EXISTS ${out})
    message(FATAL_ERROR "a failing kernel build: exit ${rc}, want 3, the error line and the log, no image\n  stderr: ${stderr}")
  endif()
  expect_error(2 ${out} "CLVR_INJECT_FAULT \"launch:0\": want"
    ${CMAKE_COMMAND} -E env CLVR_INJECT_FAULT=launch:0 ${CLVR} render -o ${out} ${SMALL})
  # A malformed limit is bad input.
  expect_error(2 ${out} "CLVR_DEVICE_MEMORY_LIMIT"
    ${CMAKE_COMMAND} -E env CLVR_DEVICE_MEMORY_LIMIT=lots ${CLVR} render -o ${out} ${SMALL})

  expect_one_stdout_line(engine-clip-torus --set options.slices=16)
  expect_one_stdout_line(torus)
endif()

if(PART STREQUAL "frames")
  # --- --orbit: 3 frames in one process; frame 0 is the plain render bit for bit, frame 1 differs.
  set(TINY ${SMALL} "--set" "volume={\"generator\":\"marschner-lobb\",\"dims\":[16,16,16]}")
  file(MAKE_DIRECTORY "${WORK}/frames")
  expect_run(0 "^wrote .*plain.png \\(64x64, slice3d" ${CLVR} render -o ${WORK}/plain.png ${TINY})
  expect_run(0 "^wrote .*f%03d.png: 3 frames \\(64x64, slice3d, [0-9.]+ ms/frame\\)\n$"
    ${CLVR} render -o ${WORK}/frames/f%03d.png ${TINY} --orbit 3 --stats ${WORK}/orbit-stats.json)
  foreach(k 000 001 002)
    expect_png(${WORK}/frames/f${k}.png 64 64)
  endforeach()
  file(SHA256 "${WORK}/plain.png" plainHash)
  file(SHA256 "${WORK}/frames/f000.png" frame0Hash)
  file(SHA256 "${WORK}/frames/f001.png" frame1Hash)
  if(NOT plainHash STREQUAL frame0Hash)
    message(FATAL_ERROR "--orbit frame 0 differs from the plain render")
  endif()
  if(plainHash STREQUAL frame1Hash)
    message(FATAL_ERROR "--orbit frame 1 equals frame 0: the camera did not turn")
  endif()
  file(READ "${WORK}/orbit-stats.json" orbitStats)
  string(JSON nframes LENGTH "${orbitStats}" frames)
  string(JSON frame2ms GET "${orbitStats}" frames 2 frame_ms)
  string(JSON frame2out GET "${orbitStats}" frames 2 output)
  string(JSON orbitN GET "${orbitStats}" orbit)
  if(NOT nframes EQUAL 3 OR NOT orbitN EQUAL 3 OR NOT frame2out MATCHES "f002.png$" OR NOT frame2ms GREATER 0)
    message(FATAL_ERROR "orbit-stats.json: want 3 frames with times and outputs:\n${orbitStats}")
  endif()
  # --single-frame renders once: the same image.
  expect_run(0 "^wrote .*single.png" ${CLVR} render -o ${WORK}/single.png ${TINY} --single-frame)
  file(SHA256 "${WORK}/single.png" singleHash)
  if(NOT singleHash STREQUAL plainHash)
    message(FATAL_ERROR "--single-frame differs from the default (first + steady frame) render")
  endif()

  # Bad patterns: exit 2, one line, and no frame file at all.
  file(REMOVE_RECURSE "${WORK}/frames")
  file(MAKE_DIRECTORY "${WORK}/frames")
  foreach(pattern "f.png" "f%d%d.png" "f%s.png" "f%03.png" "f%ld.png" "f%d%.png")
    expect_error(2 "${WORK}/frames/f0.png" "exactly one integer conversion"
      ${CLVR} render -o "${WORK}/frames/${pattern}" ${TINY} --orbit 2)
    file(GLOB written "${WORK}/frames/*")
    if(written)
      message(FATAL_ERROR "--orbit with pattern ${pattern} left files: ${written}")
    endif()
  endforeach()
  expect_error(2 "${WORK}/frames/f0.jpg" "f0.jpg: unsupported image format" ${CLVR} render -o "${WORK}/frames/f%d.jpg" ${TINY} --orbit 2)
  expect_error(2 "${WORK}/frames/f0.png" "directory .*no-dir-0 does not exist"
    ${CLVR} render -o "${WORK}/frames/no-dir-%d/f.png" ${TINY} --orbit 2)
  expect_error(2 "${WORK}/frames/f0.png" "--orbit" ${CLVR} render -o "${WORK}/frames/f%d.png" ${TINY} --orbit 0)
  file(GLOB written "${WORK}/frames/*")
  if(written)
    message(FATAL_ERROR "a failed --orbit left files: ${written}")
  endif()

  # --- the thread budget: --threads 1 (and CLVR_THREADS=1) renders the same image; PoCL runs one compute
  # unit unless POCL_CPU_MAX_CU_NUM says otherwise; bad values are bad input.
  expect_run(0 "^wrote .*threads1.png" ${CLVR} render -o ${WORK}/threads1.png ${TINY} --threads 1)
  file(SHA256 "${WORK}/threads1.png" threadsHash)
  if(NOT threadsHash STREQUAL plainHash)
    message(FATAL_ERROR "--threads 1 changed the image")
  endif()
  expect_run(0 "\\* [0-9]+: [^\n]*, 1 compute units" ${CLVR} info --threads 1 --device portable)
  expect_run(0 "\\* [0-9]+: [^\n]*, 1 compute units" ${CMAKE_COMMAND} -E env CLVR_THREADS=1 ${CLVR} info)
  cmake_host_system_information(RESULT cores QUERY NUMBER_OF_LOGICAL_CORES)
  if(cores GREATER_EQUAL 2)  # the user's own PoCL setting wins over --threads (PoCL 3.1 reads this name)
    expect_run(0 "\\* [0-9]+: [^\n]*, 2 compute units"
      ${CMAKE_COMMAND} -E env POCL_MAX_PTHREAD_COUNT=2 ${CLVR} info --threads 1)
  endif()
  expect_error(2 ${out} "--threads: want a whole number of threads" ${CLVR} render -o ${out} ${TINY} --threads 0)
  expect_error(2 ${out} "--threads: want a whole number of threads" ${CLVR} render -o ${out} ${TINY} --threads x)
  expect_error(2 ${out} "CLVR_THREADS: want a whole number of threads"
    ${CMAKE_COMMAND} -E env CLVR_THREADS=-3 ${CLVR} render -o ${out} ${TINY})

  # An image with nothing in it (a transfer function transparent everywhere) is written, with one note.
  expect_run(0 "clvr: note: the image is empty \\(alpha 0 in every pixel\\)" ${CLVR} render -o ${WORK}/empty.png ${SMALL}
    --set "transfer_function.points=[[0,1,1,1,0],[1,1,1,1,0]]" --single-frame)
  expect_png(${WORK}/empty.png 64 64)
  execute_process(COMMAND ${CLVR} render -o ${WORK}/full.png ${SMALL} --single-frame ERROR_VARIABLE fullErr OUTPUT_QUIET)
  if(fullErr MATCHES "note")
    message(FATAL_ERROR "the default scene is not empty, but: ${fullErr}")
  endif()

  # Meshes as they come (docs/meshes.md): an inverted tetrahedron is reoriented and a flat one dropped,
  # each counted in --stats and told in one stderr note; the image is still written.
  file(WRITE "${WORK}/fixed.node" "6 3 1 0\n0 0 0 0 0\n1 1 0 0 1\n2 0 1 0 2\n3 0 0 1 3\n4 1 1 1 4\n5 2 2 0 5\n")
  # tet 0 positive, tet 1 inverted (1 2 3 4 is positive), tet 2 flat (0 1 2 5, all in z = 0)
  file(WRITE "${WORK}/fixed.ele" "3 4 0\n0 0 1 2 3\n1 1 2 4 3\n2 0 1 2 5\n")
  expect_run(0 "clvr: note: the mesh had 1 zero-volume tetrahedra \\(dropped\\) and 1 inverted ones \\(reoriented\\)"
    ${CLVR} render ${SRC}/data/scenes/bluntfin.json --set "mesh={\"file\": \"${WORK}/fixed.node\"}" ${SMALL}
    --single-frame -o ${WORK}/fixed.png --stats ${WORK}/fixed.json)
  expect_png(${WORK}/fixed.png 64 64)
  file(READ "${WORK}/fixed.json" fixedStats)
  string(JSON reoriented GET "${fixedStats}" tets_reoriented)
  string(JSON degenerate GET "${fixedStats}" tets_degenerate)
  if(NOT reoriented EQUAL 1 OR NOT degenerate EQUAL 1)
    message(FATAL_ERROR "fixed.json: tets_reoriented ${reoriented}, tets_degenerate ${degenerate}, want 1 and 1")
  endif()

  # The cell-face techniques (docs/tetslice.md, docs/tetiso.md) from the command line: a small generated
  # automaton renders, bad options and a missing "iso" are one line each, no image left behind.
  set(AUTOMATON --set "mesh={\"generator\":\"automaton\",\"cells\":60,\"grid\":6}" --set image.width=32 --set image.height=32)
  expect_run(0 "wrote .*tetslice" ${CLVR} render ${SRC}/data/scenes/bluntfin-tetslice.json ${AUTOMATON}
    --set options.slices=32 --single-frame -o ${WORK}/tetslice.png)
  expect_png(${WORK}/tetslice.png 32 32)
  expect_run(0 "wrote .*tetiso" ${CLVR} render ${SRC}/data/scenes/torus-tetiso.json ${AUTOMATON}
    --single-frame -o ${WORK}/tetiso.png)
  expect_png(${WORK}/tetiso.png 32 32)
  expect_error(2 ${out} "options.slices: must be an integer in \\[1, 65536\\], got 0"
    ${CLVR} render ${SRC}/data/scenes/bluntfin-tetslice.json ${AUTOMATON} --set options.slices=0 -o ${out})
  expect_error(2 ${out} "options.weights: must be \"interpolated\" or \"equal\""
    ${CLVR} render ${SRC}/data/scenes/torus-tetiso.json ${AUTOMATON} --set options.weights='"half"' -o ${out})
  expect_error(2 ${out} "iso: technique tetiso needs \"iso\""
    ${CLVR} render ${SRC}/data/scenes/torus-tetiso.json ${AUTOMATON} --unset iso -o ${out})
  expect_error(2 ${out} "mesh.cells must be an integer"
    ${CLVR} render ${SRC}/data/scenes/torus-tetiso.json --set "mesh={\"generator\":\"automaton\",\"cells\":-4}" -o ${out})
endif()
