# The installed CMake package: `find_package(arcwheel)` and `target_link_libraries(app
# arcwheel::fitting)` in another project (README "Use from C++"; tests/consumer checks it).
# Included after every library folder, whose arcwheel_install_library calls fill the export set.
include(CMakePackageConfigHelpers)

set(ARCWHEEL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/arcwheel)
get_property(ARCWHEEL_INSTALLED_LIBRARIES GLOBAL PROPERTY ARCWHEEL_INSTALLED_LIBRARIES)

install(EXPORT arcwheelTargets NAMESPACE arcwheel:: DESTINATION ${ARCWHEEL_INSTALL_CMAKEDIR})
configure_package_config_file(cmake/arcwheelConfig.cmake.in ${PROJECT_BINARY_DIR}/arcwheelConfig.cmake
                              INSTALL_DESTINATION ${ARCWHEEL_INSTALL_CMAKEDIR})
# Before 1.0 a minor release may change the API (semantic versioning), so a request for 0.1 takes
# 0.1.x only; from 1.0 on, any release of the same major version.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(_arcwheel_compatibility SameMinorVersion)
else()
  set(_arcwheel_compatibility SameMajorVersion)
endif()
write_basic_package_version_file(${PROJECT_BINARY_DIR}/arcwheelConfigVersion.cmake
                                 COMPATIBILITY ${_arcwheel_compatibility})
install(FILES ${PROJECT_BINARY_DIR}/arcwheelConfig.cmake ${PROJECT_BINARY_DIR}/arcwheelConfigVersion.cmake
              cmake/ArcwheelSystemTargets.cmake
        DESTINATION ${ARCWHEEL_INSTALL_CMAKEDIR})
