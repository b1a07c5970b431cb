# Finds the project's dependencies, all from Debian 12 packages (./vtrack.sh installs them).

# LCM 1.3.1: Debian's lcm.pc "Requires: glib-2.0" without depending on libglib2.0-dev, so
# pkg-config fails on a minimal machine; find the header and library directly.
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp REQUIRED)
find_library(LCM_LIBRARY lcm REQUIRED)
find_program(LCM_GEN lcm-gen REQUIRED)
if(NOT TARGET vtrack_lcm)
  add_library(vtrack_lcm INTERFACE IMPORTED)
  set_target_properties(vtrack_lcm PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${LCM_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${LCM_LIBRARY}")
endif()

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(Boost 1.71 REQUIRED COMPONENTS program_options)
find_package(Threads REQUIRED)

# OpenCV: Debian's per-module -dev packages ship no OpenCVConfig.cmake (only the 100-package
# libopencv-dev meta package does), so use the config when present and find the modules otherwise.
find_package(OpenCV QUIET COMPONENTS core imgproc imgcodecs videoio)
if(NOT TARGET vtrack_opencv)
  add_library(vtrack_opencv INTERFACE IMPORTED)
  if(OpenCV_FOUND)
    set_target_properties(vtrack_opencv PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIRS}"
      INTERFACE_LINK_LIBRARIES "${OpenCV_LIBS}")
  else()
    find_path(VTRACK_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
    set(_cv_libs)
    foreach(_m core imgproc imgcodecs videoio)
      find_library(VTRACK_OPENCV_${_m}_LIBRARY opencv_${_m} REQUIRED)
      list(APPEND _cv_libs ${VTRACK_OPENCV_${_m}_LIBRARY})
    endforeach()
    set_target_properties(vtrack_opencv PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${VTRACK_OPENCV_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${_cv_libs}")
  endif()
endif()

if(VTRACK_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(VTRACK_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
if(VTRACK_BUILD_JAVA)
  find_package(Java 1.8 COMPONENTS Development)
  find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)
  if(NOT Java_JAVAC_EXECUTABLE OR NOT LCM_JAR)
    message(WARNING "javac or lcm.jar not found: the Java jar for lcm-spy is not built")
    set(VTRACK_BUILD_JAVA OFF)
  endif()
endif()
