# One shared warnings function: every first-party target calls wire_set_warnings(target).
function(wire_set_warnings target)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    set(scope INTERFACE)
  else()
    set(scope PRIVATE)
  endif()
  # BUILD_INTERFACE: our warning flags never reach projects that use the installed package.
  target_compile_options(${target} ${scope} $<BUILD_INTERFACE:-Wall> $<BUILD_INTERFACE:-Wextra>
                         $<BUILD_INTERFACE:-Wpedantic>)
  if(WIRE_WERROR)
    target_compile_options(${target} ${scope} $<BUILD_INTERFACE:-Werror>)
  endif()
endfunction()
