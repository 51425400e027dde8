# Install rules of the C++ package, written once over the folder targets (orrery_<folder>), so a
# change in which folder depends on which needs no change here:
#   cmake --install build --prefix P
# installs P/include/<folder>/*.h (so `#include "mbd/model.h"` works), P/lib/liborrery_<folder>.a,
# P/lib/cmake/Orrery/{OrreryConfig,OrreryConfigVersion,OrreryTargets}.cmake (targets
# Orrery::<folder> and Orrery::orrery, all of them), P/lib/pkgconfig/orrery.pc and P/bin/orrery.
#
# The libraries are static: their private dependencies (SUNDIALS, HDF5, FCL, ...) travel in the
# exported link interface as $<LINK_ONLY:...>, so OrreryConfig.cmake finds each package whose
# imported targets the folder targets link (find_dependency); kOrreryPackageOf below says which
# package provides which target, and configuring fails if a folder links an imported target that
# is not listed there (add one line when a folder gains a dependency).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Imported target (regex) -> find_package arguments in OrreryConfig.cmake.
set(kOrreryPackageOf
  "^Eigen3::"      "Eigen3 3.4 NO_MODULE"
  "^SUNDIALS::"    "SUNDIALS CONFIG"
  "^hdf5::"        "HDF5 COMPONENTS C"
  "^Spectra::"     "Spectra CONFIG"
  "^fcl$"          "fcl"
  "^yaml-cpp$"     "yaml-cpp"
  "^assimp::"      "assimp"
  "^OpenMP::"      "OpenMP"
  "^MPI::"         "MPI"
  "^Threads::"     "Threads")

# Headers of private dependencies (third-party libraries each folder keeps to its .cpp files). A
# project header that includes one, directly or through another project header, is internal to
# its folder and not installed (mbd/hdf5_handle.h, import/scene_reader.h, ...).
set(kOrreryPrivateIncludes "^yaml-cpp/" "^hdf5" "^H5" "^fcl/" "^sundials/" "^idas/" "^nvector/"
    "^sunmatrix/" "^sunlinsol/" "^Spectra/" "^cholmod" "^suitesparse/" "^assimp/" "^CLI/"
    "^kissfft" "^gmsh" "^mpi")

# The headers among `headers` (paths relative to the source root) that users may include.
function(_orrery_public_headers out)
  set(headers ${ARGN})
  set(internal "")
  set(changed TRUE)
  while(changed)
    set(changed FALSE)
    foreach(h ${headers})
      if(h IN_LIST internal)
        continue()
      endif()
      file(STRINGS ${PROJECT_SOURCE_DIR}/${h} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
      foreach(line ${includes})
        string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"].*" "\\1" inc "${line}")
        set(private FALSE)
        if(inc IN_LIST internal)
          set(private TRUE)
        endif()
        foreach(pattern ${kOrreryPrivateIncludes})
          if(inc MATCHES "${pattern}")
            set(private TRUE)
          endif()
        endforeach()
        if(private)
          list(APPEND internal ${h})
          set(changed TRUE)
          break()
        endif()
      endforeach()
    endforeach()
  endwhile()
  list(REMOVE_ITEM headers ${internal})
  set(${out} ${headers} PARENT_SCOPE)
  if(internal)
    message(STATUS "Orrery package: internal headers, not installed: ${internal}")
  endif()
endfunction()

# The find_package arguments for imported target `target` (error if unknown).
function(_orrery_package_of target out)
  set(pairs ${kOrreryPackageOf})
  list(LENGTH pairs n)
  math(EXPR last "${n} - 1")
  foreach(i RANGE 0 ${last} 2)
    math(EXPR j "${i} + 1")
    list(GET pairs ${i} pattern)
    list(GET pairs ${j} package)
    if(target MATCHES "${pattern}")
      set(${out} "${package}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
  message(FATAL_ERROR "orrery_install.cmake: the folder libraries link the imported target "
                      "'${target}', but kOrreryPackageOf does not say which package provides it")
endfunction()

# Folder targets in link order (users before what they use), from their own link libraries.
function(_orrery_link_order out)
  set(remaining ${ARGN})
  set(order "")
  while(remaining)
    set(progress FALSE)
    foreach(t ${remaining})
      set(used FALSE)
      foreach(u ${remaining})
        get_target_property(libs ${u} LINK_LIBRARIES)
        foreach(l ${libs})
          if(TARGET ${l})
            get_target_property(real ${l} ALIASED_TARGET)
            if(NOT real)
              set(real ${l})
            endif()
            if(real STREQUAL t)
              set(used TRUE)
            endif()
          endif()
        endforeach()
      endforeach()
      if(NOT used)
        list(APPEND order ${t})
        list(REMOVE_ITEM remaining ${t})
        set(progress TRUE)
        break()
      endif()
    endforeach()
    if(NOT progress)
      message(FATAL_ERROR "orrery_install.cmake: the folder targets depend on each other in a cycle: ${remaining}")
    endif()
  endwhile()
  set(${out} ${order} PARENT_SCOPE)
endfunction()

# Libraries a static folder target needs besides the folders: pkg-config flags (generator
# expressions resolved at generate time).
function(_orrery_private_link_flags target out)
  set(flags "")
  get_target_property(libs ${target} LINK_LIBRARIES)
  foreach(l ${libs})
    if(TARGET ${l})
      get_target_property(imported ${l} IMPORTED)
      get_target_property(type ${l} TYPE)
      if(NOT imported)
        continue()  # a folder target: listed in Libs
      endif()
      if(type STREQUAL "INTERFACE_LIBRARY")
        get_target_property(sub ${l} INTERFACE_LINK_LIBRARIES)
        foreach(s ${sub})
          if(TARGET ${s})
            get_target_property(stype ${s} TYPE)
            if(NOT stype STREQUAL "INTERFACE_LIBRARY")
              list(APPEND flags "$<TARGET_LINKER_FILE:${s}>")
            endif()
          elseif(s AND NOT s MATCHES "^\\$<|-NOTFOUND$")
            list(APPEND flags "${s}")
          endif()
        endforeach()
      else()
        list(APPEND flags "$<TARGET_LINKER_FILE:${l}>")
      endif()
    elseif(l MATCHES "^/")
      list(APPEND flags "${l}")
    elseif(l AND NOT l MATCHES "^\\$<")
      list(APPEND flags "-l${l}")
    endif()
  endforeach()
  set(${out} ${flags} PARENT_SCOPE)
endfunction()

# Installs the folder libraries `folders` (targets orrery_<folder>) with their headers, the
# all-in-one Orrery::orrery, the CMake package and the pkg-config file.
function(orrery_install_package)
  set(targets "")
  foreach(folder ${ARGN})
    if(TARGET orrery_${folder})
      list(APPEND targets orrery_${folder})
    endif()
  endforeach()

  set(packages "")
  set(all_headers "")
  foreach(t ${targets})
    string(REPLACE "orrery_" "" folder ${t})
    set_target_properties(${t} PROPERTIES EXPORT_NAME ${folder})
    # Headers from the source tree while building, from P/include once installed.
    set_property(TARGET ${t} PROPERTY INTERFACE_INCLUDE_DIRECTORIES
                 "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>"
                 "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
    install(TARGETS ${t} EXPORT OrreryTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
    file(GLOB headers RELATIVE ${PROJECT_SOURCE_DIR} ${PROJECT_SOURCE_DIR}/${folder}/*.h)
    list(APPEND all_headers ${headers})
    # Packages of the imported targets it links (publicly or, being static, privately).
    get_target_property(libs ${t} LINK_LIBRARIES)
    foreach(l ${libs})
      if(TARGET ${l})
        get_target_property(imported ${l} IMPORTED)
        if(imported)
          _orrery_package_of(${l} package)
          list(APPEND packages "${package}")
        endif()
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES packages)
  _orrery_public_headers(public_headers ${all_headers})
  foreach(h ${public_headers})
    get_filename_component(dir ${h} DIRECTORY)
    install(FILES ${PROJECT_SOURCE_DIR}/${h} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/${dir})
  endforeach()

  # Orrery::orrery: every folder library (`orrery` itself is the CLI program's name).
  add_library(orrery_all INTERFACE)
  set_target_properties(orrery_all PROPERTIES EXPORT_NAME orrery)
  target_link_libraries(orrery_all INTERFACE ${targets})
  install(TARGETS orrery_all EXPORT OrreryTargets)
  if(TARGET orrery)
    install(TARGETS orrery RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} OPTIONAL)  # if built
  endif()

  # CMake package: targets, config with its dependencies, version.
  install(EXPORT OrreryTargets NAMESPACE Orrery:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Orrery)
  set(ORRERY_FIND_DEPENDENCIES "")
  foreach(p ${packages})
    if(p MATCHES "^HDF5 ")
      # FindHDF5 compiles a C test program: C must be enabled in the user's project.
      string(APPEND ORRERY_FIND_DEPENDENCIES
             "get_property(_orrery_languages GLOBAL PROPERTY ENABLED_LANGUAGES)\n"
             "if(NOT \"C\" IN_LIST _orrery_languages)\n  enable_language(C)\nendif()\n")
    endif()
    string(APPEND ORRERY_FIND_DEPENDENCIES "find_dependency(${p})\n")
  endforeach()
  configure_package_config_file(${CMAKE_CURRENT_FUNCTION_LIST_DIR}/OrreryConfig.cmake.in
    ${PROJECT_BINARY_DIR}/package/OrreryConfig.cmake
    INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Orrery)
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/OrreryConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/package/OrreryConfig.cmake
                ${PROJECT_BINARY_DIR}/package/OrreryConfigVersion.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Orrery)

  # pkg-config: the folder libraries in link order, then what they link privately.
  _orrery_link_order(ordered ${targets})
  set(ORRERY_PC_LIBS "")
  set(ORRERY_PC_PRIVATE "")
  foreach(t ${ordered})
    string(APPEND ORRERY_PC_LIBS " -l${t}")
    _orrery_private_link_flags(${t} flags)
    foreach(f ${flags})
      string(APPEND ORRERY_PC_PRIVATE " ${f}")
    endforeach()
  endforeach()
  # Relocatable: the prefix is found from the .pc file's own place (cmake --install --prefix P).
  file(RELATIVE_PATH ORRERY_PC_PREFIX_FROM_PCDIR "/root/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/root")
  configure_file(${CMAKE_CURRENT_FUNCTION_LIST_DIR}/orrery.pc.in
                 ${PROJECT_BINARY_DIR}/package/orrery.pc.configured @ONLY)
  file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/package/orrery.pc
       INPUT ${PROJECT_BINARY_DIR}/package/orrery.pc.configured)
  install(FILES ${PROJECT_BINARY_DIR}/package/orrery.pc
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endfunction()
