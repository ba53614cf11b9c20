/* Link shim for the static `tase` of the CAN VM (tests/checks/can_vm.cmake).
 * Its capture commands use libpcap.a, whose D-Bus capture module needs
 * libdbus-1.a, which calls these two libsystemd functions to find sockets
 * handed over by socket activation. Debian ships no static libsystemd.
 * The tool never opens a D-Bus capture, and these return what libsystemd
 * returns for a process that was not socket-activated: no descriptors. */
int sd_listen_fds(int unset_environment);
int sd_is_socket(int fd, int family, int type, int listening);

int sd_listen_fds(int unset_environment)
{
    (void)unset_environment;
    return 0;
}

int sd_is_socket(int fd, int family, int type, int listening)
{
    (void)fd;
    (void)family;
    (void)type;
    (void)listening;
    return 0;
}
