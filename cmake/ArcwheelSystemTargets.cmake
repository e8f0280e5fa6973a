# arcwheel::hdf5, arcwheel::fftw3_threads and arcwheel::kdl: targets for system libraries whose packages give
# CMake variables or a bare library rather than a target. They are imported targets (nothing is
# built), so the installed package's link interfaces name them, and arcwheelConfig.cmake defines
# them from the consumer's own find_package(HDF5) and find_library, as cmake/Dependencies.cmake
# does in the build. Expects HDF5 (C), PkgConfig::FFTW3, FFTW3_THREADS_LIBRARY, Threads, orocos_kdl,
# urdfdom and OROCOS_KDL_LIBRARY found.
if(NOT TARGET arcwheel::hdf5)
  add_library(arcwheel::hdf5 INTERFACE IMPORTED)
  target_include_directories(arcwheel::hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
  target_link_libraries(arcwheel::hdf5 INTERFACE ${HDF5_C_LIBRARIES})
  target_compile_definitions(arcwheel::hdf5 INTERFACE ${HDF5_C_DEFINITIONS} ${HDF5_DEFINITIONS})
endif()
if(NOT TARGET arcwheel::fftw3_threads)
  add_library(arcwheel::fftw3_threads INTERFACE IMPORTED)
  target_link_libraries(arcwheel::fftw3_threads INTERFACE ${FFTW3_THREADS_LIBRARY} PkgConfig::FFTW3 Threads::Threads)
endif()
if(NOT TARGET arcwheel::kdl)
  # orocos KDL with the URDF parsers: only polishing/robot_kinematics.cc includes their headers.
  add_library(arcwheel::kdl INTERFACE IMPORTED)
  target_include_directories(arcwheel::kdl SYSTEM INTERFACE ${urdfdom_INCLUDE_DIRS}
                             ${orocos_kdl_INCLUDE_DIRS})
  target_link_libraries(arcwheel::kdl INTERFACE ${urdfdom_LIBRARIES} ${OROCOS_KDL_LIBRARY})
endif()
