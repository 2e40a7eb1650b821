# tests/cluster_test.cmake — `mpirun -np N clvr render` end to end (cmake -P; docs/cluster.md): the N-rank
# image equals the one-process image within 1/255 per channel (PNG) and 2e-5 (EXR, float) for N = 1..8,
# sort-last on a volume (slice3d, planes, blend) and a non-convex TetGen mesh whose k-d boxes cut through
# cells (harc), perspective, parallel and an eye inside the volume; sort-first (bands of rows, balanced by
# the previous frame's cost) gives the one-process image bit for bit (ray casters, the raster stage,
# planes, an orbit); frames mode gives the one-process orbit frames; a failure on one rank (missing scene
# file, kernel build failure, failed launch, technique that cannot render a part) gives one error line,
# the same non-zero status from mpirun, within seconds, no output.
# Inputs: CLVR, MPIEXEC, OIIOTOOL, SRC, WORK, PART. PART picks one part of the checks (volume, views,
# mesh, shaded, errors): tests/CMakeLists.txt makes each part its own CTest test (cluster.PART), so that
# ctest -j runs them side by side. Images are 64x64 or 96x96 to stay fast.
if(NOT PART MATCHES "^(volume|views|mesh|shaded|errors)$")
  message(FATAL_ERROR "PART \"${PART}\": want volume, views, mesh, shaded or errors")
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(ENV{OMPI_ALLOW_RUN_AS_ROOT} 1)  # ../shared/CLUSTER-NOTES.md: CI runs as root
set(ENV{OMPI_ALLOW_RUN_AS_ROOT_CONFIRM} 1)
# Each part's own Open MPI session directory: parts that ctest -j runs side by side would share
# /tmp/ompi.HOST.UID, and an mpirun that ends may remove it while another one starts inside it ("orte_init
# failed ... orte_session_dir failed", seen once with ctest -j2; open-mpi/ompi#8510).
file(MAKE_DIRECTORY "${WORK}/mpi")
set(ENV{OMPI_MCA_orte_tmpdir_base} "${WORK}/mpi")
set(MPI ${MPIEXEC} --oversubscribe)
set(VOLUME ${SRC}/data/scenes/default.json --set image={"width":96,"height":96,"background":[0.1,0.2,0.3]}
    --set options.slices=160)
set(MESH ${SRC}/data/scenes/l-block.json --set image={"width":96,"height":96,"background":[0.05,0.05,0.08]}
    --set mesh.max_volume=0.01)

function(run_ok)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${ARGN}\n  exit ${rc}\n  stdout: ${out}\n  stderr: ${err}")
  endif()
endfunction()

# expect_same(A B TOLERANCE [FROM_EXR]): every channel of every pixel within TOLERANCE (oiiotool --diff);
# with FROM_EXR, B is a PNG (8-bit RGB) compared with the float RGB of the EXR A clamped to [0, 1].
function(expect_same a b tolerance)
  set(pick)
  if(ARGV3 STREQUAL "FROM_EXR")
    set(pick --ch R,G,B --clamp:min=0:max=1)
  endif()
  execute_process(COMMAND ${OIIOTOOL} --fail ${tolerance} --failpercent 0 ${a} ${pick} ${b} --diff
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${b} differs from ${a} by more than ${tolerance}:\n${out}${err}")
  endif()
  string(REGEX MATCH "Max error += [^ ]*" worst "${out}")
  if(NOT worst)
    set(worst "identical")
  endif()
  message(STATUS "${b}: ${worst} (tolerance ${tolerance})")
endfunction()

# sort_last(NAME RANKS scene args...): one process and N ranks, compared as EXR (float); then a PNG (8-bit) of
# the first N above 1 against the one-process EXR: within half an 8-bit step (round to nearest) plus the
# EXR's 2e-5, so within one step of the one-process PNG, which expect_png_of checks against its EXR.
# Rank 0 writes the composited image as one process does whatever N, so one N shows the PNG path.
function(sort_last name ranks)
  run_ok(${CLVR} render ${ARGN} -o ${WORK}/${name}-1p.exr)
  foreach(n ${ranks})
    run_ok(${MPI} -np ${n} ${CLVR} render ${ARGN} -o ${WORK}/${name}-${n}.exr)
    expect_same(${WORK}/${name}-1p.exr ${WORK}/${name}-${n}.exr 2e-5)
  endforeach()
  list(FILTER ranks EXCLUDE REGEX "^1$")
  list(GET ranks 0 n)
  run_ok(${MPI} -np ${n} ${CLVR} render ${ARGN} -o ${WORK}/${name}-${n}.png)
  expect_same(${WORK}/${name}-1p.exr ${WORK}/${name}-${n}.png 0.002 FROM_EXR)  # 0.5/255 + 2e-5 = 0.00198
endfunction()

# expect_png_of(NAME scene args...): one process's PNG is its EXR (${NAME}-1p.exr, from sort_last) rounded to
# 8 bits: within half a step.
function(expect_png_of name)
  run_ok(${CLVR} render ${ARGN} -o ${WORK}/${name}-1p.png)
  expect_same(${WORK}/${name}-1p.exr ${WORK}/${name}-1p.png 0.00197 FROM_EXR)  # 0.5/255 = 0.00196
endfunction()

# sort_first(NAME ONE_PROCESS RANKS scene args...): every rank renders a band of rows of the whole data;
# the EXR equals ONE_PROCESS (a one-process EXR of the same arguments, rendered here when it is not there
# yet) bit for bit: a band takes the full image's rays (kernels/ray.h clvr_ray_window_offset).
function(sort_first name one ranks)
  if(NOT EXISTS ${one})
    run_ok(${CLVR} render ${ARGN} -o ${one})
  endif()
  foreach(n ${ranks})
    run_ok(${MPI} -np ${n} ${CLVR} render ${ARGN} --distribution sort-first -o ${WORK}/${name}-${n}.exr)
    expect_same(${one} ${WORK}/${name}-${n}.exr 0)
  endforeach()
endfunction()

# expect_job_error(RC PATTERN mpirun-args...): mpirun's status RC, exactly one "clvr: error:" line (rank 0
# speaks for all) matching PATTERN, within 60 s, and no image.
function(expect_job_error expected_rc pattern)
  file(REMOVE ${WORK}/fail.png)
  string(TIMESTAMP t0 "%s")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
  string(TIMESTAMP t1 "%s")
  math(EXPR seconds "${t1} - ${t0}")
  set(context "${ARGN}\n  exit ${rc} after ${seconds} s\n  stdout: ${out}\n  stderr: ${err}")
  if(NOT rc STREQUAL "${expected_rc}")
    message(FATAL_ERROR "${context}\n  want exit ${expected_rc}")
  endif()
  string(REGEX MATCHALL "clvr: error:" lines "${err}")  # (an error line may hold a ';', a CMake list separator)
  list(LENGTH lines count)
  if(NOT count EQUAL 1)
    message(FATAL_ERROR "${context}\n  want exactly one 'clvr: error:' line, got ${count}")
  endif()
  if(NOT err MATCHES "clvr: error: [^\n]*${pattern}")
    message(FATAL_ERROR "${context}\n  the error does not match '${pattern}'")
  endif()
  if(seconds GREATER 60 OR EXISTS ${WORK}/fail.png)
    message(FATAL_ERROR "${context}\n  took over 60 s or left ${WORK}/fail.png")
  endif()
endfunction()

# sort_last_orbit(NAME RANKS FRAMES scene args...): a sort-last orbit re-cut before every frame after the
# first (--rebalance-above 1: the parts cut by the view's estimate and the ranks' measured times, so each
# frame's parts differ), every frame equal to one process's within the sort-last tolerance; the stats count
# the re-cuts and give each frame's per-rank times.
function(sort_last_orbit name ranks frames)
  run_ok(${CLVR} render ${ARGN} --orbit ${frames} -o ${WORK}/${name}-1p-%d.exr)
  run_ok(${MPI} -np ${ranks} ${CLVR} render ${ARGN} --orbit ${frames} --distribution sort-last --rebalance-above 1
         -o ${WORK}/${name}-%d.exr --stats ${WORK}/${name}.json)
  math(EXPR last "${frames} - 1")
  foreach(k RANGE ${last})
    expect_same(${WORK}/${name}-1p-${k}.exr ${WORK}/${name}-${k}.exr 2e-5)
  endforeach()
  file(READ ${WORK}/${name}.json stats)
  string(JSON recuts GET "${stats}" recuts)
  string(JSON times LENGTH "${stats}" frames ${last} render_ms_per_rank)
  if(NOT recuts EQUAL last OR NOT times EQUAL ranks)
    message(FATAL_ERROR "${name}: ${recuts} re-cuts and ${times} times in the last frame; want ${last} and ${ranks}\n${stats}")
  endif()
endfunction()

set(SMALL64 --set image.width=64 --set image.height=64)

if(PART STREQUAL "volume")
  sort_last(volume "1;2;3;5;8" ${VOLUME})
  expect_png_of(volume ${VOLUME})
  sort_first(first-volume ${WORK}/volume-1p.exr "2;8" ${VOLUME})
  sort_last_orbit(volume-orbit 4 3 ${VOLUME})

  # Frames: an orbit of 5 frames on 3 ranks, each frame as one process renders it.
  run_ok(${CLVR} render ${VOLUME} --orbit 5 -o ${WORK}/orbit-1p-%d.png)
  run_ok(${MPI} -np 3 ${CLVR} render ${VOLUME} --orbit 5 -o ${WORK}/orbit-%d.png --stats ${WORK}/orbit.json)
  foreach(k RANGE 4)
    expect_same(${WORK}/orbit-1p-${k}.png ${WORK}/orbit-${k}.png 0)
  endforeach()
  file(READ ${WORK}/orbit.json stats)
  string(JSON ranks GET "${stats}" ranks)
  string(JSON rank4 GET "${stats}" frames 4 rank)
  if(NOT ranks EQUAL 3 OR NOT rank4 EQUAL 1)
    message(FATAL_ERROR "orbit stats: ranks ${ranks}, frame 4 on rank ${rank4}; want 3 and 1\n${stats}")
  endif()
endif()

# A blob on a 24x20x16 grid as a .pvti of two .vti pieces (ascii, cut at z = 8, sharing that layer): under
# sort-last each rank reads only the pieces its part meets (host/io/vtk_xml_io.h), and the image is one
# process's.
function(write_blob_pvti dir)
  foreach(piece 0 1)
    if(piece EQUAL 0)
      set(z0 0)
      set(z1 8)
    else()
      set(z0 8)
      set(z1 15)
    endif()
    set(values "")
    foreach(k RANGE ${z0} ${z1})
      foreach(j RANGE 19)
        foreach(i RANGE 23)
          math(EXPR v "200 - ((${i} - 11) * (${i} - 11) + (${j} - 9) * (${j} - 9) + 2 * (${k} - 7) * (${k} - 7))")
          if(v LESS 0)
            set(v 0)
          endif()
          string(APPEND values "${v} ")
        endforeach()
      endforeach()
    endforeach()
    file(WRITE "${dir}/blob_${piece}.vti" "<?xml version=\"1.0\"?>
<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">
<ImageData WholeExtent=\"0 23 0 19 ${z0} ${z1}\" Origin=\"-1 -0.8 -0.6\" Spacing=\"0.08 0.08 0.08\">
<Piece Extent=\"0 23 0 19 ${z0} ${z1}\"><PointData Scalars=\"s\">
<DataArray type=\"Int16\" Name=\"s\" format=\"ascii\">${values}</DataArray>
</PointData></Piece></ImageData></VTKFile>
")
  endforeach()
  file(WRITE "${dir}/blob.pvti" "<?xml version=\"1.0\"?>
<VTKFile type=\"PImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">
<PImageData WholeExtent=\"0 23 0 19 0 15\" GhostLevel=\"0\" Origin=\"-1 -0.8 -0.6\" Spacing=\"0.08 0.08 0.08\">
<PPointData Scalars=\"s\"><PDataArray type=\"Int16\" Name=\"s\"/></PPointData>
<Piece Extent=\"0 23 0 19 0 8\" Source=\"blob_0.vti\"/>
<Piece Extent=\"0 23 0 19 8 15\" Source=\"blob_1.vti\"/>
</PImageData></VTKFile>
")
endfunction()

if(PART STREQUAL "volume" AND VTK)
  write_blob_pvti(${WORK})
  set(BLOB ${SRC}/data/scenes/default.json --set image={"width":64,"height":64,"background":[0.1,0.2,0.3]}
      "--set=volume={\"file\": \"${WORK}/blob.pvti\"}" --unset camera
      "--set=transfer_function={\"points\": [[0, 0,0,0, 0], [100, 0.2,0.4,1, 2], [200, 1,0.8,0.3, 8]]}")
  sort_last(blob "2;3;4" ${BLOB})
  # Not an empty image on both sides: clvr notes an empty one on stderr.
  execute_process(COMMAND ${CLVR} render ${BLOB} -o ${WORK}/blob-check.png ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR err MATCHES "image is empty")
    message(FATAL_ERROR "the blob's image is empty or failed (exit ${rc}): ${err}")
  endif()
endif()

if(PART STREQUAL "views")
  sort_last(volume-parallel "2;4" ${VOLUME} --set camera.projection=\"parallel\" --set camera.parallel_scale=1.3)
  sort_last(volume-inside "3;6" ${VOLUME} --set camera.position=[0.2,0.3,0.6] --set camera.view_angle=80)
  sort_first(first-volume-inside ${WORK}/volume-inside-1p.exr "3" ${VOLUME} --set camera.position=[0.2,0.3,0.6]
             --set camera.view_angle=80)
  sort_last(mesh-parallel "3" ${MESH} --set camera.projection=\"parallel\" --set camera.parallel_scale=1.4)
  sort_first(first-mesh-parallel ${WORK}/mesh-parallel-1p.exr "3" ${MESH} --set camera.projection=\"parallel\"
             --set camera.parallel_scale=1.4)
endif()

if(PART STREQUAL "mesh")
  sort_last(mesh "1;2;4;7" ${MESH})
  expect_png_of(mesh ${MESH})
  sort_first(first-mesh ${WORK}/mesh-1p.exr "4" ${MESH})
  sort_last_orbit(mesh-orbit 3 3 ${MESH})

  # Sort-first orbit: each frame as one process renders it, the bands rebalanced from the previous frame's
  # cost (rows per rank in the stats add up to the image's height every frame).
  run_ok(${CLVR} render ${MESH} --orbit 3 -o ${WORK}/first-orbit-1p-%d.exr)
  run_ok(${MPI} -np 3 ${CLVR} render ${MESH} --orbit 3 --distribution sort-first -o ${WORK}/first-orbit-%d.exr
         --stats ${WORK}/first-orbit.json)
  file(READ ${WORK}/first-orbit.json stats)
  foreach(k RANGE 2)
    expect_same(${WORK}/first-orbit-1p-${k}.exr ${WORK}/first-orbit-${k}.exr 0)
    set(sum 0)
    foreach(r RANGE 2)
      string(JSON rows GET "${stats}" frames ${k} rows_per_rank ${r})
      if(rows LESS 1)
        message(FATAL_ERROR "sort-first orbit frame ${k}: rank ${r} has ${rows} rows\n${stats}")
      endif()
      math(EXPR sum "${sum} + ${rows}")
    endforeach()
    if(NOT sum EQUAL 96)
      message(FATAL_ERROR "sort-first orbit frame ${k}: the bands hold ${sum} rows, want 96\n${stats}")
    endif()
  endforeach()
endif()

if(PART STREQUAL "shaded")
  # Shaded techniques with two lights on a small Marschner-Lobb volume: what is checked (parts, ghost layers,
  # bands) does not depend on the volume's size, and the engine's 256x256x128 took 1-2 s to load and shade
  # per rank.
  set(SHADED ${SRC}/data/scenes/default.json ${SMALL64} --set volume.dims=[48,48,48]
      --set lights=[{"direction":[1,-0.6,0.8]},{"direction":[-0.5,-1,0.2],"color":[0.35,0.35,0.45]}]
      --set material={"ambient":0.35,"diffuse":0.75,"specular":0.4,"shininess":24})
  # planes and blend: parts with a ghost layer of points for the Sobel gradients; planes without early
  # termination (a part cannot see the opacity in front of it; with it, one process differs by <= 1 - 0.99).
  sort_last(planes "2;4" ${SHADED} --set technique=planes
            --set options={"early_termination":1,"opacity_threshold":0.002})
  sort_last(blend "3" ${SHADED} --set technique=blend --set options={"slices":256,"opacity_threshold":0.002})
  # Sort-first for the techniques sort-last cannot take too (iso3d's raster stage, planes' shading).
  sort_first(first-iso ${WORK}/first-iso-1p.exr "5" ${SHADED} --set technique=iso3d --set options={"slices":512}
             --set iso={"value":0.5,"shading":"gradient","light":[1,-0.6,0.8],"ambient":0.2,"diffuse":0.8})
  sort_first(first-planes ${WORK}/first-planes-1p.exr "3" ${SHADED} --set technique=planes
             --set options={"opacity_threshold":0.002})
endif()

if(PART STREQUAL "errors")
  set(SMALL --set image.width=64 --set image.height=64 -o ${WORK}/fail.png)
  expect_job_error(2 "rank 1: .*missing.json: no such scene file"
    ${MPI} -np 1 ${CLVR} render ${SRC}/data/scenes/default.json ${SMALL}
         : -np 1 ${CLVR} render ${WORK}/missing.json ${SMALL})
  expect_job_error(3 "rank 2: building kernels/"
    ${MPI} -np 2 ${CLVR} render ${SRC}/data/scenes/default.json ${SMALL}
         : -np 1 -x CLVR_INJECT_FAULT=build ${CLVR} render ${SRC}/data/scenes/default.json ${SMALL})
  expect_job_error(3 "CL_OUT_OF_RESOURCES .injected"
    ${MPI} -np 3 -x CLVR_INJECT_FAULT=launch:1 ${CLVR} render ${SRC}/data/scenes/default.json ${SMALL})
  expect_job_error(2 "iso3d does not render a part"
    ${MPI} -np 2 ${CLVR} render ${SRC}/data/scenes/engine-iso.json ${SMALL} --distribution sort-last)
  # Under the default distribution such a technique renders sort-first, with one note: the image of one process.
  set(ISO ${SRC}/data/scenes/engine-iso.json --set image.width=64 --set image.height=64)
  run_ok(${CLVR} render ${ISO} -o ${WORK}/iso-1p.png)
  execute_process(COMMAND ${MPI} -np 2 ${CLVR} render ${ISO} -o ${WORK}/iso-2.png RESULT_VARIABLE rc ERROR_VARIABLE err)
  string(REGEX MATCHALL "clvr: note: iso3d does not render a part of the data: sort-first" notes "${err}")
  list(LENGTH notes count)
  if(NOT rc EQUAL 0 OR NOT count EQUAL 1)
    message(FATAL_ERROR "iso3d under mpirun: exit ${rc}, ${count} notes (want 0 and 1):\n${err}")
  endif()
  expect_same(${WORK}/iso-1p.png ${WORK}/iso-2.png 0)
  expect_job_error(2 "unknown distribution \"tiles\""
    ${MPI} -np 2 ${CLVR} render ${SRC}/data/scenes/default.json ${SMALL} --distribution tiles)
endif()
