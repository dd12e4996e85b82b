# Run at install time (install(CODE) includes it; see trajroi_install_configured in
# cmake/TrajroiInstall.cmake): the paths baked into the unit, trajroi-spy and the examples
# follow the prefix given then (`cmake --install --prefix P`, CPack's /usr), not the one
# configured. /usr puts the configuration in /etc; any other prefix P in P/etc. A DESTDIR is
# honoured by file(INSTALL).
#
# In: TRAJROI_TEMPLATE, TRAJROI_OUTPUT (where the configured file is written first),
#     TRAJROI_KIND (unit | program | config | sysctl), the relative GNU dirs TRAJROI_BINDIR,
#     TRAJROI_DATADIR, TRAJROI_DOCDIR, the configure-time overrides TRAJROI_CONFIG_DIR,
#     TRAJROI_SYSTEMD_UNIT_DIR, TRAJROI_SYSCTL_DIR (empty: follow the prefix), and the
#     variables the template names.
set(prefix "${CMAKE_INSTALL_PREFIX}")
if(prefix STREQUAL "/usr")
  set(config_dir "/etc/trajroi")
else()
  set(config_dir "${prefix}/etc/trajroi")
endif()
if(TRAJROI_CONFIG_DIR)
  set(config_dir "${TRAJROI_CONFIG_DIR}")
endif()
set(unit_dir "${prefix}/lib/systemd/system")
if(TRAJROI_SYSTEMD_UNIT_DIR)
  set(unit_dir "${TRAJROI_SYSTEMD_UNIT_DIR}")
endif()
set(sysctl_dir "${prefix}/lib/sysctl.d")
if(TRAJROI_SYSCTL_DIR)
  set(sysctl_dir "${TRAJROI_SYSCTL_DIR}")
endif()

# What the templates name.
set(TRAJROID_BIN "${prefix}/${TRAJROI_BINDIR}/trajroid")
set(TRAJROI_DOC_DIR "${prefix}/${TRAJROI_DOCDIR}")
set(TRAJROI_SPY_JAR "${prefix}/${TRAJROI_DATADIR}/java/trajroi_lcmtypes.jar")
set(TRAJROI_CONFIG_DIR "${config_dir}")

if(TRAJROI_KIND STREQUAL "unit")
  set(destination "${unit_dir}")
elseif(TRAJROI_KIND STREQUAL "program")
  set(destination "${prefix}/${TRAJROI_BINDIR}")
elseif(TRAJROI_KIND STREQUAL "config")
  set(destination "${config_dir}")
elseif(TRAJROI_KIND STREQUAL "sysctl")
  set(destination "${sysctl_dir}")
else()
  message(FATAL_ERROR "InstallConfigured: unknown kind '${TRAJROI_KIND}'")
endif()
configure_file("${TRAJROI_TEMPLATE}" "${TRAJROI_OUTPUT}" @ONLY)
if(TRAJROI_KIND STREQUAL "program")
  file(INSTALL DESTINATION "${destination}" TYPE PROGRAM FILES "${TRAJROI_OUTPUT}")
else()
  file(INSTALL DESTINATION "${destination}" TYPE FILE FILES "${TRAJROI_OUTPUT}")
endif()
