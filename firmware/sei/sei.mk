# firmware/sei: the configuration protocol of the system engineering
# interface agent (docs/protocols/config.md): its messages, the commands'
# authentication, the node's server and its transfer on CAN, and the
# monitoring stream a Monitor command starts (docs/protocols/monitor.md:
# its frames, which dcos-mon decodes with the same code). Pure code:
# built for the host tests, the fuzz target and (with dcos-config) the
# host tool; it compiles for the firmware as it is, on mbedTLS's SHA-256
# (firmware/image's Sha256), and on the CAN link layer's request server.
SEI_PORTABLE_SRCS := \
	firmware/sei/src/CanSeiServer.cpp \
	firmware/sei/src/HmacSha256.cpp \
	firmware/sei/src/MonitorFrame.cpp \
	firmware/sei/src/SeiAuthenticator.cpp \
	firmware/sei/src/SeiMessage.cpp \
	firmware/sei/src/SeiMonitor.cpp \
	firmware/sei/src/SeiServer.cpp \
	firmware/sei/src/SeiStatus.cpp

# The node's side in the kernel: the backend on the card's configuration
# record and the kernel's objects, the monitoring stream's console copy,
# publications and sender, and the console command. The agent's task that runs the server is
# the flash service's (firmware/flash/src/FlashService.cpp): one task serves
# both of the agent's protocols.
SEI_TARGET_SRCS := \
	firmware/sei/src/SeiNodeBackend.cpp \
	firmware/sei/src/SeiNodeMonitor.cpp \
	firmware/sei/src/SeiCommands.cpp
