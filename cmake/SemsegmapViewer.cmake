# The page of `semsegmap view` (viewer/): its npm packages (three.js, esbuild; the lockfile is
# viewer/package-lock.json) are installed by `npm ci` into the build folder, and esbuild bundles
# them with viewer/src into one HTML page, which is compiled into the binary
# (viewer/build.mjs writes it as viewer_asset.cpp). Both run again only when their inputs change.
# Without Node.js (>= 18) and npm the viewer is left out, saying so: the rest builds and tests
# as before, and `semsegmap view` says why it is missing.
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
  set(npm_stamp ${SEMSEGMAP_VIEWER_DIR}/npm-ci.stamp)
  file(GLOB viewer_sources CONFIGURE_DEPENDS ${viewer_source}/src/*)
  file(MAKE_DIRECTORY ${SEMSEGMAP_VIEWER_DIR})
  # npm ci installs into the folder it runs in: a copy of the package files in the build folder,
  # so that build folders never share node_modules. --prefer-offline: packages already in npm's
  # cache are not asked for again.
  add_custom_command(
    OUTPUT ${npm_stamp}
    COMMAND ${CMAKE_COMMAND} -E copy ${viewer_source}/package.json ${viewer_source}/package-lock.json
            ${viewer_source}/.npmrc ${SEMSEGMAP_VIEWER_DIR}
    COMMAND ${SEMSEGMAP_NPM} ci --prefer-offline --no-audit --no-fund --loglevel=error
    COMMAND ${CMAKE_COMMAND} -E touch ${npm_stamp}
    DEPENDS ${viewer_source}/package.json ${viewer_source}/package-lock.json ${viewer_source}/.npmrc
    WORKING_DIRECTORY ${SEMSEGMAP_VIEWER_DIR}
    COMMENT "Installing the viewer's npm packages (npm ci in ${SEMSEGMAP_VIEWER_DIR})"
    VERBATIM)
  add_custom_command(
    OUTPUT ${SEMSEGMAP_VIEWER_ASSET} ${SEMSEGMAP_VIEWER_PAGE}
    COMMAND ${SEMSEGMAP_NODE} ${viewer_source}/build.mjs ${SEMSEGMAP_VIEWER_DIR}
            ${SEMSEGMAP_VIEWER_DIR}/node_modules
    DEPENDS ${npm_stamp} ${viewer_source}/build.mjs ${viewer_sources}
    COMMENT "Bundling the viewer page (three.js, esbuild)"
    VERBATIM)
  add_custom_target(semsegmap_viewer DEPENDS ${SEMSEGMAP_VIEWER_PAGE})
  message(STATUS "semsegmap: the viewer (semsegmap view) is built with node ${node_version}")
endif()
# For tests/CMakeLists.txt, which is another directory's scope.
set(SEMSEGMAP_VIEWER_BUILT ${SEMSEGMAP_VIEWER_BUILT} CACHE INTERNAL "semsegmap view is built")
set(SEMSEGMAP_VIEWER_DIR ${SEMSEGMAP_VIEWER_DIR} CACHE INTERNAL "the viewer's build folder")
