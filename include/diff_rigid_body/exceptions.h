// Typed errors of the core library. The ROS layer catches them at the
// boundary and turns them into `success=false, message=...` or a load error.
// Every message names what was wrong and where (link, body, index, field).
#pragma once

#include <stdexcept>
#include <string>

namespace diff_rigid_body
{
/// Base of every error the core throws.
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A mass or inertia tensor breaks one of the physical validity rules.
class InvalidInertiaError : public Error
{
public:
  using Error::Error;
};

/// A robot description that cannot be turned into a scene (XML, joints,
/// unknown frames, bodies or options).
class SceneDescriptionError : public Error
{
public:
  using Error::Error;
};

/// A mesh file that is missing, unreadable, empty or degenerate.
class MeshLoadError : public Error
{
public:
  using Error::Error;
};

/// A request argument that is malformed: unknown body, non-finite value,
/// wrong array size, out-of-range index or over a documented limit.
class InvalidArgumentError : public Error
{
public:
  using Error::Error;
};

}  // namespace diff_rigid_body
