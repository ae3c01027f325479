# SPDX-License-Identifier: BSD-3-Clause
# Installation (cmake --install BUILD [--prefix P]): the libraries, their public headers, the
# CMake package (find_package(isoprop [COMPONENTS render])) and the pkg-config files isoprop.pc
# and isoprop-render.pc. The package and the .pc files find the prefix from where they lie, so
# an installed tree may be moved. Components: core (libisoprop and every header but the
# renderer's and the input component's), input (libisoprop_input, the TIFF and DICOM readers
# libisoprop loads from its own folder, and input_formats.h), render (libisoprop_render and
# render.h), programs.
include(CMakePackageConfigHelpers)
set(IP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/isoprop)
set(IP_PKGCONFIG_DIR ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# ip_dependencies(OUT LIBRARIES...): for the external libraries of an installed library,
# OUT_FIND (the lines of isopropConfig.cmake that find them for the static targets),
# OUT_MODULES (pkg-config modules for Requires.private) and OUT_FLAGS (for Libs.private).
function(ip_dependencies out)
  set(find "")
  set(modules "")
  set(flags "")
  foreach(lib ${ARGN})
    if(lib STREQUAL "Threads::Threads")
      string(APPEND find "find_dependency(Threads)\n")
      list(APPEND flags ${CMAKE_THREAD_LIBS_INIT})
    elseif(lib STREQUAL "m" OR lib STREQUAL "dl")
      list(APPEND flags -l${lib})
    elseif(lib STREQUAL "stdc++")
      list(APPEND flags -lstdc++)
    elseif(lib STREQUAL "gdcmMSFF")
      # GDCM has no pkg-config module; its CMake package names the target, and the DICOM
      # input calls its MSFF, DSED and Common libraries directly.
      string(APPEND find "find_dependency(GDCM)\n")
      list(APPEND flags -lgdcmMSFF -lgdcmDSED -lgdcmCommon)
    elseif(lib STREQUAL "ZLIB::ZLIB")
      string(APPEND find "find_dependency(ZLIB)\n")
      list(APPEND modules zlib)
    elseif(lib MATCHES "^PkgConfig::(.+)$")
      # pkg_check_modules(PREFIX ... MODULE) made the target and PREFIX_MODULE_NAME
      set(prefix ${CMAKE_MATCH_1})
      set(module ${${prefix}_MODULE_NAME})
      if(NOT module)
        message(FATAL_ERROR "cmake/install.cmake: ${lib} names no single pkg-config module")
      endif()
      string(APPEND find "if(NOT TARGET ${lib})\n"
             "  find_dependency(PkgConfig)\n"
             "  pkg_check_modules(${prefix} REQUIRED QUIET IMPORTED_TARGET ${module})\n"
             "endif()\n")
      list(APPEND modules ${module})
    else()
      message(FATAL_ERROR "cmake/install.cmake: no rule to find ${lib} for the installed "
                          "package; add one to ip_dependencies()")
    endif()
  endforeach()
  string(REPLACE ";" " " modules "${modules}")
  string(REPLACE ";" " " flags "${flags}")
  set(${out}_FIND "${find}" PARENT_SCOPE)
  set(${out}_MODULES "${modules}" PARENT_SCOPE)
  set(${out}_FLAGS "${flags}" PARENT_SCOPE)
endfunction()
# the static library holds the input component's readers: it needs their libraries too
ip_dependencies(IP_CORE_DEPENDS ${IP_STATIC_LIBRARIES})
ip_dependencies(IP_INPUT_DEPENDS ${IP_INPUT_LIBRARIES})
ip_dependencies(IP_RENDER_DEPENDS ${IP_RENDER_LIBRARIES})

# libraries and headers
install(TARGETS isoprop_shared isoprop EXPORT isopropTargets COMPONENT core
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS isoprop_render_shared isoprop_render EXPORT isopropRenderTargets COMPONENT render
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS isoprop_input_shared EXPORT isopropInputTargets COMPONENT input
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
set(IP_CORE_HEADER_EXCLUDES "")
foreach(part RENDER INPUT)
  set(IP_${part}_HEADER_FILES "")
  foreach(header ${IP_${part}_HEADERS})
    list(APPEND IP_CORE_HEADER_EXCLUDES PATTERN ${header} EXCLUDE)
    list(APPEND IP_${part}_HEADER_FILES ${CMAKE_SOURCE_DIR}/include/isoprop/${header})
  endforeach()
endforeach()
install(DIRECTORY ${CMAKE_SOURCE_DIR}/include/isoprop DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT core ${IP_CORE_HEADER_EXCLUDES})
install(FILES ${IP_RENDER_HEADER_FILES} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/isoprop
        COMPONENT render)
install(FILES ${IP_INPUT_HEADER_FILES} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/isoprop
        COMPONENT input)

# the CMake package
install(EXPORT isopropTargets NAMESPACE isoprop:: DESTINATION ${IP_CMAKE_DIR} COMPONENT core)
install(EXPORT isopropRenderTargets NAMESPACE isoprop:: DESTINATION ${IP_CMAKE_DIR}
        COMPONENT render)
install(EXPORT isopropInputTargets NAMESPACE isoprop:: DESTINATION ${IP_CMAKE_DIR}
        COMPONENT input)
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/isopropConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/package/isopropConfig.cmake
                              INSTALL_DESTINATION ${IP_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/isopropConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_BINARY_DIR}/package/isopropConfig.cmake
              ${CMAKE_BINARY_DIR}/package/isopropConfigVersion.cmake
        DESTINATION ${IP_CMAKE_DIR} COMPONENT core)

# the pkg-config files
file(RELATIVE_PATH IP_PC_TO_PREFIX ${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
string(REGEX REPLACE "/$" "" IP_PC_TO_PREFIX "${IP_PC_TO_PREFIX}")
foreach(pc isoprop isoprop-render isoprop-input)
  configure_file(${CMAKE_SOURCE_DIR}/cmake/${pc}.pc.in ${CMAKE_BINARY_DIR}/package/${pc}.pc @ONLY)
endforeach()
install(FILES ${CMAKE_BINARY_DIR}/package/isoprop.pc DESTINATION ${IP_PKGCONFIG_DIR}
        COMPONENT core)
install(FILES ${CMAKE_BINARY_DIR}/package/isoprop-render.pc DESTINATION ${IP_PKGCONFIG_DIR}
        COMPONENT render)
install(FILES ${CMAKE_BINARY_DIR}/package/isoprop-input.pc DESTINATION ${IP_PKGCONFIG_DIR}
        COMPONENT input)
