# Installing trajroi: paths that follow the install-time prefix.
set(TRAJROI_CONFIG_DIR "" CACHE PATH
    "Where the daemon's configuration is installed and read (empty: /etc/trajroi for the prefix /usr, else PREFIX/etc/trajroi)")
set(TRAJROI_SYSTEMD_UNIT_DIR "" CACHE PATH "Where trajroid.service is installed (empty: PREFIX/lib/systemd/system)")
set(TRAJROI_SYSCTL_DIR "" CACHE PATH "Where the sysctl drop-in is installed (empty: PREFIX/lib/sysctl.d)")

# trajroi_install_configured(TEMPLATE NAME KIND [VARS var...]): configures TEMPLATE at install
# time (cmake/InstallConfigured.cmake) and installs it as NAME where KIND says (unit, program,
# config, sysctl). VARS: configure-time variables the template also names.
function(trajroi_install_configured template name kind)
  cmake_parse_arguments(ARG "" "" "VARS" ${ARGN})
  set(code "")
  foreach(var IN ITEMS TRAJROI_CONFIG_DIR TRAJROI_SYSTEMD_UNIT_DIR TRAJROI_SYSCTL_DIR ${ARG_VARS})
    string(APPEND code "set(${var} \"${${var}}\")\n")
  endforeach()
  string(APPEND code
    "set(TRAJROI_TEMPLATE \"${template}\")\n"
    "set(TRAJROI_OUTPUT \"${CMAKE_CURRENT_BINARY_DIR}/install/${name}\")\n"
    "set(TRAJROI_KIND ${kind})\n"
    "set(TRAJROI_BINDIR \"${CMAKE_INSTALL_BINDIR}\")\n"
    "set(TRAJROI_DATADIR \"${CMAKE_INSTALL_DATADIR}\")\n"
    "set(TRAJROI_DOCDIR \"${CMAKE_INSTALL_DOCDIR}\")\n"
    "include(\"${PROJECT_SOURCE_DIR}/cmake/InstallConfigured.cmake\")\n")
  install(CODE "${code}")
endfunction()
