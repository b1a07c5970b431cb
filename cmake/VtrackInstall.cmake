# cmake --install: executables, the core and message libraries with their headers, the generated
# message headers, the jar, and a CMake package so that other projects can find_package(vtrack).
include(CMakePackageConfigHelpers)

install(TARGETS vtrack_msgs vtrack_base vtrack_core EXPORT vtrackTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${VTRACK_GENERATED_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vtrack)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/tracker/core/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vtrack/tracker/core
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/base/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vtrack/base
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lcmtypes/util/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vtrack/lcmtypes/util
  FILES_MATCHING PATTERN "*.h")
install(FILES ${VTRACK_LCM_FILES_ALL} DESTINATION ${CMAKE_INSTALL_DATADIR}/vtrack/lcmtypes)
if(VTRACK_BUILD_JAVA)
  install(FILES ${VTRACK_JAR} DESTINATION ${CMAKE_INSTALL_DATADIR}/java)
endif()
install(PROGRAMS ${PROJECT_SOURCE_DIR}/scripts/vtrack-netns DESTINATION ${CMAKE_INSTALL_BINDIR})
if(EXISTS ${PROJECT_SOURCE_DIR}/config)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${CMAKE_INSTALL_DATADIR}/vtrack/config)
endif()

install(EXPORT vtrackTargets NAMESPACE vtrack:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vtrack)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vtrackConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/vtrackConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vtrack
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/vtrackConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vtrackConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/vtrackConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vtrack)

# systemd unit templates and their environment file (deploy/README.md): share/vtrack/systemd.
# The units are configured at install time, so that their paths follow the prefix actually used
# (`cmake --install build --prefix P`); component `systemd` installs them alone.
find_program(LCM_LOGGER_EXECUTABLE lcm-logger)
if(NOT LCM_LOGGER_EXECUTABLE)
  set(LCM_LOGGER_EXECUTABLE /usr/bin/lcm-logger)
endif()
file(GLOB VTRACK_UNIT_TEMPLATES ${PROJECT_SOURCE_DIR}/deploy/systemd/*.service.in)
install(CODE "
  set(VTRACK_UNIT_BINDIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  set(VTRACK_UNIT_DATADIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/vtrack\")
  set(LCM_LOGGER_EXECUTABLE \"${LCM_LOGGER_EXECUTABLE}\")
  foreach(in ${VTRACK_UNIT_TEMPLATES})
    get_filename_component(unit \"\${in}\" NAME_WLE)
    configure_file(\"\${in}\" \"${CMAKE_CURRENT_BINARY_DIR}/systemd/\${unit}\" @ONLY)
    file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/vtrack/systemd\"
      TYPE FILE FILES \"${CMAKE_CURRENT_BINARY_DIR}/systemd/\${unit}\")
  endforeach()" COMPONENT systemd)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/vtrack.env ${PROJECT_SOURCE_DIR}/deploy/README.md
  DESTINATION ${CMAKE_INSTALL_DATADIR}/vtrack/systemd COMPONENT systemd)
