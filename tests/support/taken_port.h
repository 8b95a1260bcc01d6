// TakenPort: a loopback TCP port this object listens on, so that no one else can, until it
// is destroyed; for tests of what a program does when its port is taken, or (once released)
// when nothing listens there.
#pragma once

namespace cohaptic::testing {

class TakenPort {
 public:
  TakenPort();  ///< port() is -1 if no socket could be bound
  ~TakenPort();
  TakenPort(const TakenPort&) = delete;
  TakenPort& operator=(const TakenPort&) = delete;

  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = -1;
};

/// A loopback port nothing listens on: taken, then released.
int closed_port();

}  // namespace cohaptic::testing
