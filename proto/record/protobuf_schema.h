// Schemas of protobuf messages for MCAP's protobuf encoding
// (https://mcap.dev/spec/registry#protobuf): a Schema record whose encoding is
// "protobuf", whose name is the message's full name ("cohaptic.wire.ToolSample") and
// whose data is a serialized google.protobuf.FileDescriptorSet holding the message's
// .proto file and every file it imports, directly or not, each once, every file after the
// files it depends on. A reader can rebuild the message type from it alone (with a
// DescriptorPool and DynamicMessageFactory), without the generated C++ class.
#pragma once

#include <string>

namespace google::protobuf {
class Descriptor;
}

namespace cohaptic::record {

/// The serialized FileDescriptorSet for `descriptor` (see above).
std::string protobuf_schema_data(const google::protobuf::Descriptor* descriptor);

/// The schema name of a protobuf message: its full name, e.g. "cohaptic.wire.ToolSample".
std::string schema_name(const google::protobuf::Descriptor* descriptor);

}  // namespace cohaptic::record
