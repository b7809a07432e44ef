// Bounded decoding of service requests, in front of roscpp's own.
//
// roscpp deserialises a request before the callback runs, and its array
// reader resizes to the length prefix *before* it checks that the message
// holds that many elements; for fixed-size elements it computes the byte
// count as uint32_t(sizeof(T) * n), which wraps. So a 40-byte request
// claiming 2^29 + 1 doubles makes the node allocate and zero 4 GiB.
//
// BoundedRequest<R> wraps a generated request type R with the same md5sum,
// datatype and definition (clients see no change), and a deserialiser that
// walks R's fields with a stream checking every length prefix first: an
// array of n elements needs n * (smallest encoding of one element) bytes
// left in the message, and n <= kMaxArrayElements. A request that breaks
// either is not decoded further; `refusal` names the field, and the node
// answers success=false with it (the connection stays usable).
#pragma once

#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <boost/array.hpp>
#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/service_traits.h>

namespace diff_rigid_body
{
/// The most elements any request array may declare: 3 per vertex for the
/// largest vertex request (RequestLimits::kMaxVertices = 2^22).
constexpr std::uint32_t kMaxArrayElements = 3u << 22;

template <typename Request>
struct BoundedRequest
{
  Request request;
  std::string refusal;  ///< "" when the request was decoded whole
};

namespace detail
{
/// Top-level field names of a message definition, in order (constants and
/// the definitions of nested types after "===" are skipped).
std::vector<std::string> topLevelFieldNames(const std::string& definition);

/// Thrown inside the bounded stream; caught by the deserialiser.
struct RequestRefusal
{
  std::string message;
};

/// A read-only stream with roscpp's `next()` interface that checks sizes
/// before it allocates, and knows which top-level field it is reading.
class BoundedIStream
{
public:
  BoundedIStream(const std::uint8_t* data, std::uint32_t size, const std::vector<std::string>* names)
    : data_(data), left_(size), names_(names)
  {
  }

  template <typename T>
  typename std::enable_if<ros::message_traits::IsFixedSize<T>::value && !ros::message_traits::IsMessage<T>::value>::type
  next(T& value)
  {
    enterField();
    take(&value, sizeof(T));
    leaveField();
  }

  void next(std::string& text)
  {
    enterField();
    const std::uint32_t n = count(1);
    text.assign(reinterpret_cast<const char*>(data_), n);
    skip(n);
    leaveField();
  }

  template <typename T, typename A>
  void next(std::vector<T, A>& values)
  {
    enterField();
    const std::uint32_t n = count(smallestEncoding<T>());
    values.resize(n);
    for (T& value : values)
      next(value);
    leaveField();
  }

  template <typename T, std::size_t N>
  void next(boost::array<T, N>& values)
  {
    enterField();
    for (T& value : values)
      next(value);
    leaveField();
  }

  template <typename M>
  typename std::enable_if<ros::message_traits::IsMessage<M>::value>::type next(M& message)
  {
    enterField();
    ros::serialization::Serializer<M>::template allInOne<BoundedIStream, M&>(*this, message);
    leaveField();
  }

private:
  /// Bytes of the smallest encoding of one element of type T: an empty
  /// string or array takes 4, a fixed-size type its size, a message the
  /// encoding of a default one.
  template <typename T>
  static std::uint32_t smallestEncoding()
  {
    return std::max<std::uint32_t>(1, ros::serialization::serializationLength(T()));
  }

  void enterField()
  {
    if (depth_++ == 0)
      ++field_;
  }
  void leaveField() { --depth_; }

  // Reads a length prefix of elements whose encodings take at least
  // `element_bytes` each, and checks it before anything is allocated.
  std::uint32_t count(std::uint32_t element_bytes)
  {
    std::uint32_t n = 0;
    take(&n, sizeof n);
    if (n > kMaxArrayElements || std::uint64_t(n) * element_bytes > left_)
    {
      std::ostringstream why;
      why << "request field '" << fieldName() << "': declares " << n << " elements";
      if (n > kMaxArrayElements)
        why << ", over the limit of " << kMaxArrayElements;
      else
        why << ", but only " << left_ << " bytes follow";
      why << " (refused before decoding)";
      throw RequestRefusal{ why.str() };
    }
    return n;
  }

  void take(void* out, std::uint32_t bytes)
  {
    if (bytes > left_)
      throw RequestRefusal{ "request field '" + fieldName() + "': the message ends early" };
    std::memcpy(out, data_, bytes);
    skip(bytes);
  }

  void skip(std::uint32_t bytes)
  {
    data_ += bytes;
    left_ -= bytes;
  }

  std::string fieldName() const
  {
    const std::size_t index = field_ == 0 ? 0 : field_ - 1;
    return names_ && index < names_->size() ? (*names_)[index] : "#" + std::to_string(index);
  }

  const std::uint8_t* data_;
  std::uint32_t left_;
  const std::vector<std::string>* names_;
  int depth_ = 0;
  std::size_t field_ = 0;
};
}  // namespace detail
}  // namespace diff_rigid_body

namespace ros
{
namespace serialization
{
template <typename Request>
struct Serializer<diff_rigid_body::BoundedRequest<Request>>
{
  template <typename Stream>
  static void read(Stream& stream, diff_rigid_body::BoundedRequest<Request>& bounded)
  {
    static const std::vector<std::string> names =
        diff_rigid_body::detail::topLevelFieldNames(ros::message_traits::definition<Request>());
    diff_rigid_body::detail::BoundedIStream bounded_stream(stream.getData(), stream.getLength(), &names);
    try
    {
      Serializer<Request>::template allInOne<diff_rigid_body::detail::BoundedIStream, Request&>(bounded_stream,
                                                                                                   bounded.request);
    }
    catch (const diff_rigid_body::detail::RequestRefusal& refusal)
    {
      bounded.request = Request();
      bounded.refusal = refusal.message;
    }
  }
  template <typename Stream>
  static void write(Stream& stream, const diff_rigid_body::BoundedRequest<Request>& bounded)
  {
    Serializer<Request>::write(stream, bounded.request);
  }
  static std::uint32_t serializedLength(const diff_rigid_body::BoundedRequest<Request>& bounded)
  {
    return Serializer<Request>::serializedLength(bounded.request);
  }
};
}  // namespace serialization

// Same identity as the wrapped request, so the service's md5sum and types
// are those of the generated srv.
#define DRB_TRAIT_OF_THE_WRAPPED_REQUEST(traits, Trait)                                                             \
  template <typename Request>                                                                                      \
  struct traits::Trait<diff_rigid_body::BoundedRequest<Request>> : traits::Trait<Request>                          \
  {                                                                                                                \
  };
DRB_TRAIT_OF_THE_WRAPPED_REQUEST(message_traits, MD5Sum)
DRB_TRAIT_OF_THE_WRAPPED_REQUEST(message_traits, DataType)
DRB_TRAIT_OF_THE_WRAPPED_REQUEST(message_traits, Definition)
DRB_TRAIT_OF_THE_WRAPPED_REQUEST(service_traits, MD5Sum)
DRB_TRAIT_OF_THE_WRAPPED_REQUEST(service_traits, DataType)
#undef DRB_TRAIT_OF_THE_WRAPPED_REQUEST
}  // namespace ros
