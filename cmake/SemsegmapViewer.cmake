# The page of `semsegmap view` (viewer/): its npm packages (three.js, esbuild; the lockfile is
# viewer/package-lock.json) are installed by scripts/setup.sh (`npm ci` into viewer/node_modules:
# the build downloads nothing), and esbuild bundles them with viewer/src into one HTML page,
# which is compiled into the binary (viewer/build.mjs writes it as viewer_asset.cpp), again only
# when its inputs change. Without Node.js (>= 18) or the installed packages the viewer is left
# out, saying so: the rest builds and tests as before, and `semsegmap view` says why it is missing.
option(SEMSEGMAP_WITH_VIEWER "The 3D viewer page (semsegmap view), bundled with Node.js and npm" ON)
set(SEMSEGMAP_VIEWER_BUILT OFF)
set(SEMSEGMAP_VIEWER_DIR ${CMAKE_BINARY_DIR}/viewer)
if(SEMSEGMAP_WITH_VIEWER)
  find_program(SEMSEGMAP_NODE node)
  find_program(SEMSEGMAP_NPM npm)
  set(node_version "")
  if(SEMSEGMAP_NODE)
    execute_process(COMMAND ${SEMSEGMAP_NODE} --version OUTPUT_VARIABLE node_version
                    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    string(REGEX REPLACE "^v" "" node_version "${node_version}")
  endif()
  if(NOT SEMSEGMAP_NODE OR NOT SEMSEGMAP_NPM)
    message(STATUS "semsegmap: the viewer (semsegmap view) is left out: node and npm were not "
                   "found (scripts/setup.sh installs them)")
  elseif(NOT EXISTS ${PROJECT_SOURCE_DIR}/viewer/node_modules/.package-lock.json)
    message(STATUS "semsegmap: the viewer (semsegmap view) is left out: its npm packages are not "
                   "installed (scripts/setup.sh runs npm ci in viewer/)")
  elseif(node_version VERSION_LESS 18)
    message(STATUS "semsegmap: the viewer (semsegmap view) is left out: node ${node_version} is "
                   "older than 18, which esbuild needs")
  else()
    set(SEMSEGMAP_VIEWER_BUILT ON)
  endif()
else()
  message(STATUS "semsegmap: the viewer (semsegmap view) is left out (SEMSEGMAP_WITH_VIEWER=OFF)")
endif()

if(SEMSEGMAP_VIEWER_BUILT)
  set(viewer_source ${PROJECT_SOURCE_DIR}/viewer)
  set(SEMSEGMAP_VIEWER_ASSET ${SEMSEGMAP_VIEWER_DIR}/viewer_asset.cpp)
  set(SEMSEGMAP_VIEWER_PAGE ${SEMSEGMAP_VIEWER_DIR}/viewer.html)
  set(npm_stamp ${viewer_source}/node_modules/.package-lock.json)  # written by npm ci
  file(GLOB viewer_sources CONFIGURE_DEPENDS ${viewer_source}/src/*)
  file(MAKE_DIRECTORY ${SEMSEGMAP_VIEWER_DIR})
  add_custom_command(
    OUTPUT ${SEMSEGMAP_VIEWER_ASSET} ${SEMSEGMAP_VIEWER_PAGE}
    COMMAND ${SEMSEGMAP_NODE} ${viewer_source}/build.mjs ${SEMSEGMAP_VIEWER_DIR}
            ${viewer_source}/node_modules
    DEPENDS ${npm_stamp} ${viewer_source}/build.mjs ${viewer_sources}
    COMMENT "Bundling the viewer page (three.js, esbuild)"
    VERBATIM)
  add_custom_target(semsegmap_viewer DEPENDS ${SEMSEGMAP_VIEWER_PAGE})
  message(STATUS "semsegmap: the viewer (semsegmap view) is built with node ${node_version}")
endif()
# For tests/CMakeLists.txt, which is another directory's scope.
set(SEMSEGMAP_VIEWER_BUILT ${SEMSEGMAP_VIEWER_BUILT} CACHE INTERNAL "semsegmap view is built")
set(SEMSEGMAP_VIEWER_DIR ${SEMSEGMAP_VIEWER_DIR} CACHE INTERNAL "the viewer's build folder")
