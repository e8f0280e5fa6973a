# Every third-party package arcwheel uses, all from Debian (scripts/install_deps.sh installs them).
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Ceres REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(OpenSSL REQUIRED COMPONENTS Crypto)
find_package(Threads REQUIRED)
# Boost (header-only): Boost.Math's distributions (the chi-square test in core/statistics.cc, the
# coverage factor in uncertainty/budget.cc) and Boost.Random's portable normal deviates.
find_package(Boost 1.74 REQUIRED)
# qhull: the Delaunay triangulation of scattered error maps (polishing/error_map_scattered.cc),
# its reentrant C library (Qhull::qhull_r), as scipy.spatial.Delaunay uses it.
find_package(Qhull REQUIRED)
# The robot's kinematics (polishing/robot_kinematics.cc): orocos KDL and the URDF parser urdfdom.
# (Debian's kdl_parser, which joins the two, links some fifty ROS libraries that every start of the
# program would load: robot_kinematics.cc makes the chain from urdfdom's links itself.)
find_package(orocos_kdl REQUIRED)
# Its package names the library by a bare name (orocos-kdl): found as a path, as an installed
# package's link interface needs.
find_library(OROCOS_KDL_LIBRARY orocos-kdl REQUIRED)
find_package(urdfdom REQUIRED)
if(ARCWHEEL_BUILD_PYTHON)
  # Debian's interpreter, which has numpy, h5py and matplotlib (scripts/packages.txt); a python3
  # earlier on the PATH (pyenv) may lack them.
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "The Python interpreter the module is built for")
  find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module)
  find_package(pybind11 2.10 CONFIG REQUIRED)
endif()
if(ARCWHEEL_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(ARCWHEEL_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# cairo draws the report plots to SVG, PNG and PDF from one drawing code (reports/).
find_package(PkgConfig REQUIRED)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)
# The results store (store/): SQLite by default, PostgreSQL's client library for a server.
pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
pkg_check_modules(LIBPQ REQUIRED IMPORTED_TARGET libpq)
# FFTW: the dwell solve's removal products as FFT convolutions (polishing/removal_fft.h).
pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3)
# FFTW's threads library (the same Debian package, no pkg-config file of its own): the large
# transforms of the dwell solve run on every core.
find_library(FFTW3_THREADS_LIBRARY fftw3_threads HINTS ${FFTW3_LIBRARY_DIRS} REQUIRED)
# HDF5's CMake module gives variables, FFTW's threads a bare library: wrap them as targets, the
# same way here and in the installed package (arcwheelConfig.cmake).
include(${CMAKE_CURRENT_LIST_DIR}/ArcwheelSystemTargets.cmake)
