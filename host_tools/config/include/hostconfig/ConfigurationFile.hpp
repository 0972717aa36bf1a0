// A node's configuration as a TOML file (`dcos-config save` and `restore`,
// docs/guide/configure.md, "Saving and restoring a node"): the card's
// configuration record (node id, CAN bit rate, closed queries, lockout,
// kernel command line) and the objects and tasks the node should have
// beside its application's: named semaphores, message ports and
// publishers, and tasks of the image's entry points. Pure code: the text in,
// the values out, every error with its line.
#pragma once

#include <hostconfig/ConfigRequest.hpp>
#include <hostconfig/NodeObjects.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hostconfig {

/// What a saved file holds.
struct SavedNode {
    /// The record to write (its sequence is the node's business).
    NodeConfiguration configuration;
    /// The node the file was saved from, for the reader; 0 when unknown.
    uint32_t serial = 0;
    std::vector<ObjectSpec> objects;
    std::vector<TaskSpec> tasks;
};

/// The file's text; @p header is written as comment lines at its top.
std::string writeSavedNode(const SavedNode& node, const std::string& header);

/// Reads @p text (the file @p fileName's) into @p out; the error with file
/// and line when it is not a configuration this tool can restore: not
/// TOML, an unknown key, a value out of its range, a name too long, two
/// objects of one kind with one name.
std::optional<std::string> readSavedNode(const std::string& text, const std::string& fileName, SavedNode& out);

} // namespace hostconfig
